"""The step after a joint's kink (numerics.loop.run_motion, W.h_after).

After a kink the run loop starts no larger than the step its controller proposed after the
first step that followed the same joint's last kink in the same direction. Without that
memory the step carried over a joint's re-closure is often too large for its stiff elastic
branch: over the first 6 s of rdk_01 at 0.2 g on the 8-drum column of the CI band, the
first attempt after a kink was rejected 656 times in 2,387 (27 %) without it, 188 in 2,417
(8 %) with it (over 10 s: 53 % and 16 %). Counted on the run loop's own source run
uncompiled, its step and the column's switch wrapped (as tools/profile_methods.py --events
does); the bound, 15 %, lies between the two.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

from rbm_cli.base.jit import plain
from rbm_cli.config.load import load_config, parse_config
from rbm_cli.config.points import expand
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.rbm.pieces import KINK
from rbm_cli.models.rbm.step import stepper
from rbm_cli.models.registry import make_runner
from rbm_cli.numerics.rk import TAB_NS

from .paths import CONFIGS, ROOT

#: Seconds of the record run uncompiled (about 40 s of test time; its joints first open
#: after 4 s).
SECONDS = 6.0


def _first_point():
    config = load_config(CONFIGS / "ci" / "suite_multidrum_ci.yaml")
    point = next(iter(expand(config, parse_config, base_dir=config.base_dir)))
    cfg = point.config
    solver = dataclasses.replace(cfg.solver, method="DOP853", implementation="python")
    return dataclasses.replace(cfg, solver=solver)


def _cut(motion, t_stop):
    knots = np.asarray(motion.knots)
    keep = knots < t_stop
    t_last = float(knots[keep][-1])
    return dataclasses.replace(motion, knots=knots[keep], values=np.asarray(motion.values)[keep],
                               t_end=t_last, pulse_end=min(motion.pulse_end, t_last))  # fmt: skip


def count_first_attempts() -> tuple[int, int, str]:
    """(steps after a kink, of them rejected at their first attempt, the run's status)."""
    cfg = _first_point()
    motion = _cut(make_ground_motion(cfg.excitation, 0.2), SECONDS)
    loop_names = getattr(stepper.run_plane, "py_func", stepper.run_plane).__globals__
    attempt, switch = plain(loop_names["attempt_step"]), plain(stepper.switch)
    compiled = loop_names["attempt_step"], stepper.switch
    last = ["none"]
    after_kink = []  # whether the first attempt of each step after a kink was rejected

    def counted_attempt(mc, t, y, f, h_abs, *rest):
        res = attempt(mc, t, y, f, h_abs, *rest)
        if last[0] == "kink":
            after_kink.append(res[4] > TAB_NS[mc])
        last[0] = "none"
        return res

    def counted_switch(*args):
        what = switch(*args)
        last[0] = "kink" if what == KINK else "other"
        return what

    loop_names["attempt_step"], stepper.switch = counted_attempt, counted_switch
    try:
        out = make_runner(cfg).run(motion, cfg.solver)
    finally:
        loop_names["attempt_step"], stepper.switch = compiled
    return len(after_kink), int(sum(after_kink)), out.status


@pytest.mark.slow
def test_first_steps_after_kinks_are_mostly_taken():
    # in a fresh interpreter: the names it wraps are those a first uncompiled run copies
    code = ("from tests.test_step_after_event import count_first_attempts as c;"
            " print(*c())")  # fmt: skip
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, timeout=600, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    steps, rejected, status = done.stdout.split()[-3:]
    steps, rejected = int(steps), int(rejected)
    assert status == "survived"
    assert steps > 300  # the joints chatter: the count says something
    share = rejected / steps
    assert share < 0.15, f"{share:.0%} of the first attempts after a kink rejected"
