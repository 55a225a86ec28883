"""FOO returns outcome1 three times, then outcome2; BAR returns outcome1, back to FOO; the machine ends in 'end'.

Run it with ``python examples/foo_bar.py`` or ``fsmscope run examples/foo_bar.py``.
"""

import fsm as smach


class Foo(smach.State):
    def __init__(self) -> None:
        smach.State.__init__(self, outcomes=["outcome1", "outcome2"])
        self.counter = 0

    def execute(self, userdata):
        smach.loginfo("Executing state FOO")
        if self.counter < 3:
            self.counter += 1
            return "outcome1"
        return "outcome2"


class Bar(smach.State):
    def __init__(self) -> None:
        smach.State.__init__(self, outcomes=["outcome1"])

    def execute(self, userdata):
        smach.loginfo("Executing state BAR")
        return "outcome1"


def build() -> smach.StateMachine:
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("FOO", Foo(), transitions={"outcome1": "BAR", "outcome2": "end"})
        smach.StateMachine.add("BAR", Bar(), transitions={"outcome1": "FOO"})
    return sm


def main() -> str:
    outcome = build().execute()
    print("foo_bar finished with outcome: %s" % outcome)
    return outcome


if __name__ == "__main__":
    main()
