"""`mbjax_harness.timing.in_turns`: the functions called in turns after a warm-up each, each timed
by the fastest of its calls."""

import time

from mbjax_harness.timing import in_turns


def test_in_turns_alternates_and_keeps_the_fastest():
    calls = []
    delays = {"a": iter([0.0, 0.05, 0.01, 0.03]), "b": iter([0.0, 0.0, 0.02, 0.0])}

    def run(name):
        def call():
            calls.append(name)
            time.sleep(next(delays[name]))
        return call

    seconds = in_turns({"a": run("a"), "b": run("b")}, 3)
    assert calls == ["a", "b"] + ["a", "b"] * 3          # warm-ups, then turns
    assert 0.01 <= seconds["a"] < 0.03                    # the fastest of 0.05, 0.01, 0.03
    assert seconds["b"] < 0.01
