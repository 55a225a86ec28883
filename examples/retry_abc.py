"""A, B and C each succeed with a 50% chance; any failure goes back to A.

Each state counts its runs in userdata (A_count, B_count, C_count); the counts are
printed after the run. The chance is seedable: ``--seed N`` or the FSMSCOPE_SEED
environment variable (unseeded by default).
"""

import argparse
import os
import random

import fsm as smach


class Coin(smach.State):
    """Succeeds with probability ``p`` and counts its runs in ``<name>_count``."""

    def __init__(self, name: str, rng: random.Random, p: float = 0.5) -> None:
        self.key = name + "_count"
        smach.State.__init__(self, outcomes=["succeeded", "failed"], io_keys=[self.key])
        self.name = name
        self.rng = rng
        self.p = p

    def execute(self, userdata):
        userdata[self.key] = userdata[self.key] + 1
        ok = self.rng.random() < self.p
        smach.loginfo("%s %s (run %d)" % (self.name, "succeeded" if ok else "failed", userdata[self.key]))
        return "succeeded" if ok else "failed"


def build(seed: int | None = None) -> smach.StateMachine:
    rng = random.Random(seed)
    sm = smach.StateMachine(outcomes=["succeeded"], output_keys=["A_count", "B_count", "C_count"])
    sm.userdata.A_count = 0
    sm.userdata.B_count = 0
    sm.userdata.C_count = 0
    with sm:
        smach.StateMachine.add("A", Coin("A", rng), transitions={"succeeded": "B", "failed": "A"})
        smach.StateMachine.add("B", Coin("B", rng), transitions={"succeeded": "C", "failed": "A"})
        smach.StateMachine.add("C", Coin("C", rng), transitions={"succeeded": "succeeded", "failed": "A"})
    return sm


def main(argv: list[str] | None = None) -> tuple[str, dict]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    env_seed = os.environ.get("FSMSCOPE_SEED")
    parser.add_argument("--seed", type=int, default=int(env_seed) if env_seed else None)
    args = parser.parse_args(argv)
    sm = build(args.seed)
    outcome = sm.execute()
    counts = {k: sm.userdata[k] for k in ("A_count", "B_count", "C_count")}
    print("retry_abc finished with outcome: %s" % outcome)
    print("A_count=%(A_count)d B_count=%(B_count)d C_count=%(C_count)d" % counts)
    return outcome, counts


if __name__ == "__main__":
    main()
