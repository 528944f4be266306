"""Benchmark suites for `mbjax bench SUITE` (their timing helper is `mbjax_harness.timing`).

Each suite is run(out: Path, quick: bool) -> list of records, written as out/SUITE.jsonl and
out/SUITE.png. Peers (MuJoCo, Pinocchio, exudyn, Crocoddyl) are measured in the same process when installed.
"""

from mbjax_harness.bench import (accuracy, compile_time, contact, flexible, integrators, loops, mpc,
                                 rigid, speed, tfe, throughput, trajopt, wrist)

SUITES = {
    accuracy.NAME: accuracy.run,
    compile_time.NAME: compile_time.run,
    contact.NAME: contact.run,
    flexible.NAME: flexible.run,
    integrators.NAME: integrators.run,
    loops.NAME: loops.run,
    mpc.NAME: mpc.run,
    rigid.NAME: rigid.run,
    speed.NAME: speed.run,
    tfe.NAME: tfe.run,
    throughput.NAME: throughput.run,
    trajopt.NAME: trajopt.run,
    wrist.NAME: wrist.run,
}

__all__ = ["SUITES"]
