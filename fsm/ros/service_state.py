"""ServiceState: call a bus service from a state machine, as smach_ros's ServiceState does."""

import functools
from typing import Any, Callable, Iterable

from ..core import log
from .bus import Bus, ServiceException, get_bus
from .preemptible import PreemptibleState
from .slots import set_slot, store
from .user_callback import FAILED, UserCallback


class ServiceState(PreemptibleState):
    """Builds a request from userdata and callbacks, calls the service, stores the response.

    Outcomes: succeeded, aborted, preempted, plus ``outcomes`` and a cb_interface
    response_cb's. Failures (missing keys, a raising callback, a failing call) give
    'aborted', never an exception. ``service_spec()``, when given, builds the default
    request; otherwise it is an empty dict. A default request is built fresh for every
    execution (smach_ros kept one across runs).
    """

    def __init__(self, service_name: str, service_spec: Callable[[], Any] | None = None,
                 request: Any = None, request_cb: Callable[..., Any] | None = None,
                 request_cb_args: list = [], request_cb_kwargs: dict = {}, request_key: str | None = None,
                 request_slots: list[str] = [],
                 response_cb: Callable[..., Any] | None = None, response_cb_args: list = [],
                 response_cb_kwargs: dict = {}, response_key: str | None = None,
                 response_slots: list[str] = [],
                 input_keys: list[str] = [], output_keys: list[str] = [], outcomes: Iterable[str] = [],
                 bus: Bus | None = None) -> None:
        PreemptibleState.__init__(self, outcomes=["succeeded", "aborted", "preempted"])
        self._service_name = service_name
        self._service_spec = service_spec
        self._request = request
        self._bus = get_bus(bus)
        owner = "service " + service_name
        self._request_cb = UserCallback(self, owner, "request", request_cb, request_cb_args, request_cb_kwargs,
                                        input_keys, output_keys)
        self._response_cb = UserCallback(self, owner, "response", response_cb, response_cb_args,
                                         response_cb_kwargs, input_keys, output_keys, returns_outcome=True)
        self._request_key = request_key
        self._request_slots = list(request_slots)
        self._response_key = response_key
        self._response_slots = list(response_slots)
        self.register_input_keys(input_keys + request_slots + ([request_key] if request_key is not None else []))
        self.register_output_keys(output_keys + response_slots + ([response_key] if response_key is not None else []))
        self.register_outcomes(outcomes)

    def execute(self, ud: Any) -> str:
        name = self._service_name
        if self.preempt_requested():
            log.loginfo("Preempting %s before sending request." % name)
            self.service_preempt()
            return "preempted"
        if not self._wait_for(functools.partial(self._bus.wait_for_service, name), None,
                              "Still waiting for service '%s'..." % name):
            if self.preempt_requested():
                log.loginfo("Preempting while waiting for service '%s'." % name)
                self.service_preempt()
                return "preempted"
            log.logwarn("Terminated while waiting for service '%s'." % name)
            return "aborted"

        request = self._initial_request()
        if self._request_key is not None:
            if self._request_key not in ud:
                log.logerr("Requested request key '%s' not in userdata struture. Available keys are: %s"
                           % (self._request_key, list(ud.keys())))
                return "aborted"
            request = ud[self._request_key]
        for key in self._request_slots:
            if key not in ud:
                log.logerr("Requested request slot key '%s' is not in userdata strcture. Available keys are: %s"
                           % (key, list(ud.keys())))
                return "aborted"
            set_slot(request, key, ud[key])
        request = self._request_cb.update(ud, request)
        if request is FAILED:
            return "aborted"
        if request is None:
            log.logerr("Attempting to call service " + name + " with no request")
            return "aborted"

        try:
            log.logdebug("Calling service %s with request:\n%s" % (name, request))
            response = self._bus.call_service(name, request)
        except ServiceException as ex:
            log.logerr("Exception when calling service '%s': %s" % (name, ex))
            return "aborted"

        outcome = self._response_cb.run(ud, response)
        if outcome is FAILED:
            return "aborted"
        store(ud, response, self._response_key, self._response_slots)
        return outcome if outcome is not None else "succeeded"

    def _initial_request(self) -> Any:
        if self._request is not None:
            return self._request
        return self._service_spec() if self._service_spec is not None else {}
