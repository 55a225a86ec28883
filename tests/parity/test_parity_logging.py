"""BEHAVIORS.md section A, the original SMACH and fsm side by side: the loggers and the errors'
own lines (the start, transition, termination, Concurrence and Iterator lines are compared with
the runs of the other modules)."""

import fsm

from parity_support import kit, outcome_of


def test_the_default_loggers_print_each_level_with_its_prefix(parity, original, capsys):
    printed = []
    for sm in (original, fsm):
        sm.loginfo("i")
        sm.logwarn("w")
        sm.logdebug("d")
        sm.logerr("e")
        sm.InvalidStateError("printed when made")
        printed.append(capsys.readouterr().out)
    assert printed[1] == printed[0] == ("[  INFO ] : i\n[  WARN ] : w\n[ DEBUG ] : d\n[ ERROR ] : e\n"
                                        "[ ERROR ] : InvalidStateError: printed when made\n")


def test_set_loggers_takes_info_warn_debug_error_and_the_runtime_logs_through_them(parity):
    def scenario(side):
        sm = side.sm
        sm.loginfo("i")
        sm.logwarn("w")
        sm.logdebug("d")
        sm.logerr("e")
        ud = sm.UserData()
        return outcome_of(lambda: ud.missing)
    same = parity.same(scenario)
    assert same["logs"] == [("info", "i"), ("warn", "w"), ("debug", "d"), ("error", "e"),
                            ("error", "Userdata key 'missing' not available. Available keys are: []")]


def test_every_smach_error_logs_itself_when_made_even_if_caught(parity):
    def scenario(side):
        sm = side.sm
        made = []
        for kind in (sm.InvalidStateError, sm.InvalidTransitionError, sm.InvalidUserCodeError,
                     sm.InvalidConstructionError):
            try:
                raise kind("made and caught")
            except Exception as err:  # the original does not export SmachError from smach
                made.append((type(err).__name__, str(err), isinstance(err, Exception)))
        return made
    same = parity.same(scenario)
    assert same["logs"] == [("error", "%s: made and caught" % kind) for kind in (
        "InvalidStateError", "InvalidTransitionError", "InvalidUserCodeError", "InvalidConstructionError")]


def test_a_failed_consistency_check_logs_the_error_then_that_the_check_failed(parity):
    def scenario(side):
        sm = side.sm
        k = kit(sm)
        built = sm.StateMachine(outcomes=["done"])
        with built:
            sm.StateMachine.add("A", k.Out("go"), {"go": "NOWHERE"})
        return outcome_of(built.execute)
    same = parity.same(scenario)
    assert same["result"] == ("returned", None)
    errors = [message for level, message in same["logs"] if level == "error"]
    assert errors[-2].startswith("InvalidTransitionError: State machine failed consistency check: \n\tState 'A' "
                                 "references unknown states: ['NOWHERE']\n\n\tAvailable states: ")
    assert errors[-1] == "Container consistency check failed."
