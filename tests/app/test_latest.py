"""LatestCall, "the newest request wins", without Qt: a batch waiting is replaced, a batch under way stops
before its next call, every call that ran is answered. The tests wait for events, never for time."""

import threading

from gcmh_studio.latest import LatestCall


class Answers:
    def __init__(self):
        self.got = []
        self.cond = threading.Condition()

    def __call__(self, key, value, error):
        with self.cond:
            self.got.append((key, value, error))
            self.cond.notify_all()

    def wait_for(self, key):
        with self.cond:
            assert self.cond.wait_for(lambda: any(k == key for k, _, _ in self.got), timeout=30)


def test_answers_value_and_error():
    answers = Answers()
    calls = LatestCall(answers)
    calls.submit([("a", lambda: 1), ("b", lambda: 1 / 0), ("c", lambda: 3)])
    answers.wait_for("c")
    assert answers.got[0] == ("a", 1, None)
    assert answers.got[1][0] == "b" and answers.got[1][1] is None and "division" in answers.got[1][2]
    assert answers.got[2] == ("c", 3, None)


def test_newest_batch_wins():
    answers = Answers()
    calls = LatestCall(answers)
    release = threading.Event()
    started = threading.Event()

    def slow():
        started.set()
        assert release.wait(30)
        return "slow"

    calls.submit([("first", slow), ("rest of the first batch", lambda: "stale")])
    assert started.wait(30)
    calls.ask("older", lambda: "dropped")   # waiting: replaced by the next question, never run
    calls.ask("newest", lambda: "new")
    assert calls.busy()
    release.set()
    answers.wait_for("newest")
    assert [k for k, _, _ in answers.got] == ["first", "newest"]
    with answers.cond:   # the thread ends when nothing is left
        answers.cond.wait_for(lambda: not calls.busy(), timeout=30)
    assert not calls.busy()


def test_a_receiver_gone_ends_the_thread():
    def gone(key, value, error):
        raise RuntimeError("wrapped C/C++ object has been deleted")

    done = threading.Event()
    calls = LatestCall(gone, name="test-receiver-gone")
    calls.submit([("a", lambda: 1), ("b", done.set)])
    for thread in [t for t in threading.enumerate() if t.name == "test-receiver-gone"]:
        thread.join(30)
    assert not calls.busy() and not done.is_set()
