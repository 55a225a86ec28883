"""A robot that builds a new machine per episode, run by the fleet tests as a user's script
(`fsmscope run robots/episodes.py --zenoh ROBOT`): ten machines one after the other, each
PICK -> PLACE -> done; then the process stays until it is stopped, as a robot waiting for work."""
import time

import fsm

EPISODES = 10


class Step(fsm.State):
    def __init__(self):
        fsm.State.__init__(self, ["go"])

    def execute(self, ud):
        time.sleep(0.02)
        return "go"


def build() -> fsm.StateMachine:
    sm = fsm.StateMachine(["done"])
    with sm:
        fsm.StateMachine.add("PICK", Step(), {"go": "PLACE"})
        fsm.StateMachine.add("PLACE", Step(), {"go": "done"})
    return sm


for _ in range(EPISODES):
    build().execute()
while True:
    time.sleep(1)
