"""Controlling a machine: the ``Controls`` every kind of machine implements and ``Refused``, the one
refusal, carrying the HTTP status a server answers it with (``controls``); a machine of this
process's (``handle``, with its debugger's in ``debug``); and the control frames another process
sends to ask for them and their answers (``frames``: what the websocket publisher and the Zenoh
robot both apply). Each control is recorded as a ``control`` event of the machine."""
