"""Controlling a machine of this process: preempt, hold, initial state, start (``handle``), the
debugger's controls (``debug``), and the control frames another process sends to ask for them and
their answers (``frames``: what the websocket publisher and the Zenoh robot both apply). Each
control is recorded as a ``control`` event of the machine. A refusal is a ``ControlError`` whose
``status`` is the HTTP status a server answers it with, also what the frames' answers carry."""
