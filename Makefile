# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
VENV     := .venv
PY       := $(VENV)/bin/python
STAMP    := $(VENV)/.installed
# Debian packages the tests and the demo need: Graphviz's dot for graph layout, Chromium and
# Firefox ESR for the browser tests, openssl for the fleet's TLS test certificates, and ROS 1 as
# Debian packages it for the tests of a real ROS 1 robot (tests/ros1/): rospy, a master, rostopic,
# genpy and std_msgs's .msg files (to generate smach_msgs' classes), actionlib (smach_ros imports it),
# std_srvs (examples/tutorial_service_action.py's service).
APT_PKGS := graphviz chromium firefox-esr fonts-dejavu-core openssl \
            python3-rospy python3-rosmaster python3-rostopic python3-rosbag python3-genpy python3-genmsg \
            python3-std-msgs ros-std-msgs python3-actionlib python3-roslaunch python3-std-srvs

.PHONY: install apt demo test test-fast bench clean

install: apt $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e '.[sim,test]'
	touch $(STAMP)

apt:
	@missing=""; for p in $(APT_PKGS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "installing Debian packages:$$missing"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	  else \
	    echo "missing Debian packages:$$missing (run 'sudo make apt' or install them)"; \
	  fi; \
	fi

demo: install
	$(VENV)/bin/fsmscope demo

# Three xdist workers on two cores (the tests wait on browsers, robots and real time more than they
# compute): each takes a whole module at a time, the demo layer goes to one (tests/conftest.py).
# docs/benchmarks.md has the suite's time; `pytest -q` alone runs it in one process.
test: install
	$(PY) -m pytest -q -n 3

# The unit layer alone: the runtime, the logs and the formats, no server, no browser (under a minute).
test-fast: install
	$(PY) -m pytest -q -n 3 -m unit

# Every benchmark prints a table (medians) against its target; all of them take ~20 minutes.
bench: install
	$(PY) bench/runtime.py
	$(PY) bench/replay.py
	$(PY) bench/timetravel.py
	$(PY) bench/timetravel_browser.py
	$(PY) bench/live_rewind.py
	$(PY) bench/debugger.py
	$(PY) bench/big_machine_browser.py
	$(PY) bench/first_view_browser.py
	$(PY) bench/server.py
	$(PY) bench/graph.py
	$(PY) bench/sim.py
	$(PY) bench/demo_cpu.py
	$(PY) bench/bag_import.py
	$(PY) bench/mcap_export.py
	$(PY) bench/fleet_cost.py
	$(PY) bench/original_smach.py --instructions
	$(PY) bench/watched.py
	$(PY) bench/fleet_dashboard.py

clean:
	rm -rf $(VENV) *.egg-info .pytest_cache
