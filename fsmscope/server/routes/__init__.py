"""The app's routes, one router per concern (docs/api.md): pages, machines, control, stream, ingest."""
