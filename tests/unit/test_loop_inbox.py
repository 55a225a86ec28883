"""The hand-off from the fleet watcher's threads to the dashboard's event loop (fsmscope/server/cli/fleet_bridge.py)."""

import asyncio
import concurrent.futures
import threading

from fsmscope.server.cli.loop_inbox import LoopInbox


def run_in_thread(work) -> None:
    thread = threading.Thread(target=work)
    thread.start()
    thread.join()


def on_own_loop(main):
    """``main()`` run by an event loop of its own thread (the suite's thread may run one)."""
    with concurrent.futures.ThreadPoolExecutor(1) as own_loop:
        return own_loop.submit(asyncio.run, main()).result()


def test_calls_posted_from_a_thread_run_on_the_loop_in_order_at_the_wake():
    async def main():
        inbox = LoopInbox(asyncio.get_running_loop())
        loop_thread = threading.current_thread()
        ran = []

        def post_then_wake():
            for i in range(3):
                inbox.post(lambda i=i: ran.append((i, threading.current_thread() is loop_thread)))
            inbox.wake()

        run_in_thread(post_then_wake)
        for _ in range(100):
            await asyncio.sleep(0.01)
            if len(ran) == 3:
                break
        return ran

    assert on_own_loop(main) == [(0, True), (1, True), (2, True)]


def test_posting_does_not_wake_the_loop_and_one_wake_runs_everything_posted():
    async def main():
        loop = asyncio.get_running_loop()
        inbox = LoopInbox(loop)
        ran = []
        woken = []
        real = loop.call_soon_threadsafe
        loop.call_soon_threadsafe = lambda *a: (woken.append(a), real(*a))[1]
        run_in_thread(lambda: [inbox.post(ran.append, i) for i in range(5)])
        await asyncio.sleep(0.05)
        before = (list(ran), len(woken))
        run_in_thread(lambda: (inbox.wake(), inbox.wake()))
        await asyncio.sleep(0.05)
        return before, ran, len(woken)

    before, ran, wakes = on_own_loop(main)
    assert before == ([], 0)
    assert ran == [0, 1, 2, 3, 4]
    assert wakes == 1
