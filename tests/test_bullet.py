"""`model: bullet`: stacked rigid drums in PyBullet's contact dynamics.

Expected values come from outside the engine: the frustum's mass, centroid and
corner inertia from the independent polynomial integrals of `housner`
(themselves checked against triple integrals in test_reference.py), Housner's
impact formula e = 1 - 1.5 sin^2(alpha) written here, the statics of a rigid
block (no motion below tan(alpha) g), and Housner's model itself run with the
engine's measured impact loss. CI runs the study's 6 x 5 grid with 3 s of
excitation per cell (tools/make_engine.py runs it for 10 s).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli
from rbm_cli.config.load import parse_config
from rbm_cli.config.types import G
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.bullet.engine import PhysicsClient
from rbm_cli.models.bullet.geometry import drum_solids, stack_slenderness
from rbm_cli.models.bullet.run import (
    EngineSettings,
    bullet_run,
    impact_rate_ratios,
    measure_restitution,
)
from rbm_cli.models.bullet.scene import (
    Frame,
    StackGeometry,
    build_scene,
    joint_friction,
    keep_in_plane,
    read_frame,
)
from rbm_cli.structures.block import block_geometry
from rbm_cli.structures.restitution import block_restitution
from rbm_cli.study.simulate import simulate

#: Slow (whole domains re-made, processes killed, contact-engine runs):
#: `pytest -m 'not slow'` leaves this file out.
pytestmark = pytest.mark.slow

BLOCK = {"height": 4.0, "base_width": 1.0, "depth": 1.0}  # Spanos-Koh slender, H/B = 4
TAPER = {"height": 5.0, "base_width": 0.96, "top_width": 0.66}  # the paper's column


def config(column, model="bullet", duration=10.0, **interface):
    data = {
        "name": "t",
        "model": model,
        "column": dict(column),
        "excitation": {"type": "harmonic", "duration": duration},
    }
    if interface:
        data["interface"] = interface
    return parse_config(data)


def harmonic(amplitude_g, frequency_hz, duration):
    w = 2 * math.pi * frequency_hz
    return GroundMotion("harmonic", amplitude_g * G, w, 0.0, duration, duration)


# ---------------------------------------------------------------------- geometry


@pytest.mark.parametrize("column", [BLOCK, TAPER, {**TAPER, "section": "circular"}])
def test_drum_solid_matches_the_true_block(column):
    """Mass, centre of mass and corner inertia of the monolith's solid equal the
    independent integrals of `housner` (guards the inertia handed to Bullet)."""
    cfg = config(column)
    (drum,) = drum_solids(cfg.column)
    geo = block_geometry(cfg.column)
    assert drum.mass == pytest.approx(geo.mass, rel=1e-12)
    assert drum.centre == pytest.approx(geo.centre_height, rel=1e-12)
    corner = drum.inertia[1] + drum.mass * (geo.half_base**2 + drum.centre**2)
    assert corner == pytest.approx(geo.corner_inertia, rel=1e-12)
    assert stack_slenderness((drum,))[0] == pytest.approx(geo.slenderness, rel=1e-12)


def test_drums_add_up_to_the_monolith():
    """Eight drums have the monolith's mass and centre of mass; a box drum's
    inertias are m (h^2 + w^2) / 12 and m (2 w^2) / 12 (square section)."""
    mono = drum_solids(config(TAPER).column)[0]
    drums = drum_solids(config({**TAPER, "drums": 8}).column)
    mass = sum(d.mass for d in drums)
    centre = sum(d.mass * (d.bottom + d.centre) for d in drums) / mass
    assert mass == pytest.approx(mono.mass, rel=1e-12)
    assert centre == pytest.approx(mono.centre, rel=1e-12)
    (box,) = drum_solids(config(BLOCK).column)
    m = 2700.0 * 4.0
    assert box.box and box.mass == pytest.approx(m)
    assert box.inertia == pytest.approx((m * 17 / 12, m * 17 / 12, m * 2 / 12))


# --------------------------------------------------------------------- impacts


def housner_e(height, width):
    """Housner (1963): e = 1 - 1.5 sin^2(alpha) for a uniform rectangle."""
    return 1.0 - 1.5 * math.sin(math.atan(width / height)) ** 2


def test_impact_loss_is_housners():
    """The engine's own impact loss on a 4 x 1 m block (restitution 0 at the
    contact points), read from the energy of successive rocking peaks, is
    Housner's 0.912 to within 0.002 at every impact (measured: 0.9116-0.9121)."""
    ratios = measure_restitution(config(BLOCK), tilt_fraction=0.5, impacts=4)
    assert len(ratios) == 4
    assert np.all(np.abs(ratios - housner_e(4.0, 1.0)) < 0.002), ratios


def test_impact_loss_follows_slenderness():
    """A squat block loses more at an impact than a slender one, as Housner's
    formula says (0.70 at H/B = 2 against 0.91 at H/B = 4); guards a loss that
    ignores geometry. (The earlier reading from the rates around the impact
    gave 0.60-0.70 here, biased by the contact's position correction.)"""
    thick = measure_restitution(config({**BLOCK, "height": 2.0}), impacts=3)
    assert np.all(np.abs(thick - housner_e(2.0, 1.0)) < 0.004), thick


def test_rate_reading_of_the_impact_is_biased_by_erp():
    """Why rbm reads e from the peaks: the angular velocity fitted in the 0.5-2.5 ms
    after an impact still carries Bullet's push-out of the contact penetration
    (erp; no split impulse for multibody contacts), so on the tapered column it
    reads below Housner's e and moves with erp; the peaks' energy does not."""
    cfg = config(TAPER)
    e_h = block_restitution(block_geometry(cfg.column))
    rates = impact_rate_ratios(cfg, impacts=4)
    assert np.min(rates) < e_h - 0.005, rates
    for erp in (0.2, 0.05):
        peaks = measure_restitution(cfg, impacts=4, settings=EngineSettings(erp=erp))
        assert np.all(np.abs(peaks - e_h) < 0.001), (erp, peaks)


def test_split_impulse_does_not_reach_multibody_contacts():
    """Bullet's split impulse is not applied to multibody contacts (the branch is
    commented out in btMultiBodyConstraintSolver::setupMultiBodyContactConstraint):
    switching it off leaves free rocking bit for bit the same. Guards the
    statement in docs/engine.md for the installed PyBullet."""
    solids = drum_solids(config(TAPER).column)
    alpha = stack_slenderness(solids)[0]
    states = []
    with PhysicsClient() as client:
        p, cid = client.module, client.id
        for split in (1, 0):
            bodies = build_scene(client, solids, EngineSettings(), 0.5 * alpha)
            p.setPhysicsEngineParameter(useSplitImpulse=split, physicsClientId=cid)
            p.setGravity(0.0, 0.0, -G, physicsClientId=cid)
            for k in range(1, 15001):  # 1.5 s: two impacts
                p.stepSimulation(physicsClientId=cid)
                keep_in_plane(p, cid, bodies, pose=k % 10 == 0)
            states.append(read_frame(p, cid, bodies))
    assert abs(states[0].tilts[0]) > 1e-3  # still rocking
    assert np.array_equal(states[0].centres, states[1].centres)
    assert np.array_equal(states[0].rates, states[1].rates)


def test_in_plane_reset_returns_what_the_engine_reads_back():
    """keep_in_plane(pose=True) returns the frame it leaves, so the 1 ms checks
    skip a second round of engine calls; it must equal what read_frame reads
    (guards that shortcut)."""
    solids = drum_solids(config({**TAPER, "drums": 3}).column)
    with PhysicsClient() as client:
        p, cid = client.module, client.id
        bodies = build_scene(client, solids, EngineSettings(), 0.3 * stack_slenderness(solids)[0])
        p.setGravity(-0.5 * G, 0.0, -G, physicsClientId=cid)
        for _ in range(2000):
            p.stepSimulation(physicsClientId=cid)
        left = keep_in_plane(p, cid, bodies, pose=True)
        back = read_frame(p, cid, bodies)
    assert np.abs(left.rates).max() > 1e-3  # moving
    for name in ("centres", "rotations", "rates", "speeds"):
        assert np.array_equal(getattr(left, name), getattr(back, name)), name


# ------------------------------------------------------------------------- runs


def test_rest_below_the_uplift_level():
    """Below tan(alpha) g the rigid block cannot move (statics): the engine,
    run without the shortcut, keeps it still, and the shortcut skips the run."""
    cfg = config(BLOCK, duration=2.0)
    motion = harmonic(0.9 * 0.25, 2.0, 2.0)  # tan(alpha) = B / H = 0.25
    out, history = bullet_run(cfg, motion, record=True, output_dt=0.01)
    assert out.status == "survived"
    assert np.max(np.abs(history.rotations)) < 1e-4
    assert np.max(out.max_ratio) < 1e-3
    skipped = simulate(cfg, 0.9 * 0.25, 2.0)
    assert skipped.status == "survived" and skipped.n_steps == 0
    # friction demand: the block moves with the ground, T / N = a_g / g (statics;
    # the 10 ms mean forces keep a little of the contact's chatter)
    assert out.friction[0] == pytest.approx(0.9 * 0.25, abs=0.002)
    assert skipped.friction_demand == pytest.approx((0.9 * 0.25,), rel=1e-12)


def test_friction_demand_is_capped_by_coulomb_when_sliding():
    """A squat block (uplift at 0.5 g) with friction 0.2 under 0.4 g slides: the
    mobilised |T| / N of its base reaches the friction coefficient and no more
    (Coulomb's cone: Bullet's pyramid let the 8-drum joints reach 1.41 x friction)."""
    cfg = config({"height": 2.0, "base_width": 1.0, "depth": 1.0}, duration=1.0, friction=0.2)
    r = simulate(cfg, 0.4, 1.0)
    assert r.status == "survived"
    assert r.friction_demand[0] == pytest.approx(0.2, rel=1e-3)
    assert float(r.message.split("base ")[1].split(" mm")[0]) > 10.0  # it slid


def test_big_pulse_collapses_and_is_reported():
    """A 4 x 1 m block under 1 g at 0.5 Hz overturns within the first cycles
    (Housner's model does too); collapse time, base joint and ratio reported."""
    r = simulate(config(BLOCK, duration=6.0), 1.0, 0.5)
    ref = simulate(config(BLOCK, model="housner", duration=6.0, restitution=0.91), 1.0, 0.5)
    assert r.status == ref.status == "collapsed"
    assert r.collapse_interface == 1
    assert r.t_collapse_s == pytest.approx(ref.t_collapse_s, abs=0.05)
    assert r.max_rotation_ratio >= 1.0
    assert "max slip" in r.message


def test_multidrum_run_records_drum_positions():
    """An 8-drum column runs; its history holds n + 1 node positions and n tilts,
    and the top moves more than the base node (guards the node order)."""
    cfg = config({**TAPER, "drums": 8}, duration=1.5)
    r = simulate(cfg, 0.5, 1.5, record=True, output_dt=0.01)
    h = r.history
    assert h.node_displacements.shape == (len(h.t), 9)
    assert h.rotations.shape == (len(h.t), 8)
    assert np.max(np.abs(h.node_displacements[:, -1])) > np.max(np.abs(h.node_displacements[:, 0]))
    assert r.n_steps == 15000


def test_same_cell_same_answer():
    """Runs are reproducible (the engine is reset between runs): a sweep's
    file must not depend on what a worker ran before."""
    cfg = config(TAPER, duration=3.0)
    a = simulate(cfg, 0.5, 1.0)
    simulate(config(BLOCK, duration=1.0), 0.6, 2.0)
    b = simulate(cfg, 0.5, 1.0)
    # the same fields, NaN where one is NaN (t_collapse_s of a survivor, friction_demand)
    ra, rb = a.row(), b.row()
    assert ra.keys() == rb.keys()
    assert all(ra[k] == rb[k] or (ra[k] != ra[k] and rb[k] != rb[k]) for k in ra), (ra, rb)
    assert a.status == b.status == "survived" and math.isnan(a.row()["friction_demand"])


# ------------------------------------------------------------ against Housner

#: The study's 6 x 5 harmonic grid (the one tools/make_engine.py runs for 10 s).
GRID_AMPLITUDES = (0.3, 0.5, 0.7, 0.9, 1.1, 1.3)  # g
GRID_FREQUENCIES = (0.5, 1.0, 1.5, 2.0, 2.5)  # Hz
#: CI runs it with 3 s of excitation instead of 10 s (both models see the same motion).
CI_DURATION = 3.0  # s


@pytest.mark.parametrize("column", [BLOCK, TAPER], ids=["block", "tapered"])
def test_engine_agrees_with_housner(column):
    """The 95 % bar: a monolithic block and the tapered column agree with
    `housner` (run with the engine's measured impact loss) on >= 95 % of the cells
    of a 6 x 5 harmonic grid (here 3 s of excitation; 10 s in docs/engine.md)."""
    engine = config(column, duration=CI_DURATION)
    e = float(np.mean(measure_restitution(engine, impacts=4)))
    ref = config(column, model="housner", duration=CI_DURATION, restitution=round(e, 4))
    cells = [(a, f) for a in GRID_AMPLITUDES for f in GRID_FREQUENCIES]
    same = [simulate(engine, a, f).status == simulate(ref, a, f).status for a, f in cells]
    assert sum(same) >= 0.95 * len(cells), [c for c, ok in zip(cells, same, strict=True) if not ok]


# ------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    ("friction", "message"),
    [
        (0, "interface.friction must be a number > 0"),
        # Bullet caps a contact's friction at 10: a larger interface.friction would
        # run silently with 10, so it is refused in one line
        (20, "interface.friction must be <= 10"),
    ],
)
def test_bad_friction_is_one_line(tmp_path, friction, message):
    path = tmp_path / "c.yaml"
    path.write_text(
        "name: x\nmodel: bullet\ncolumn: {height: 4, base_width: 1}\n"
        f"interface: {{friction: {friction}}}\n"
    )
    result = CliRunner().invoke(cli, ["run", str(path), "-a", "0.5", "-f", "1"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.output
    assert "Traceback" not in result.output


def test_rbm_run_writes_the_engine_history(tmp_path):
    """`rbm run` on an engine config writes the RBM's four files, the history from
    the drums' positions (8 drums: 9 node columns, 8 rotations)."""
    path = tmp_path / "c.yaml"
    path.write_text(
        "name: e\nmodel: bullet\ncolumn: {height: 5, base_width: 0.96, top_width: 0.66,"
        " drums: 8}\nexcitation: {duration: 0.5}\n"
    )
    res = CliRunner().invoke(cli, ["run", str(path), "-a", "0.6", "-f", "2", "-o", str(tmp_path)])
    assert res.exit_code == 0, res.output
    folder = tmp_path / "e" / "run_A0.6_f2"
    for name in ("history.csv", "history.png", "shapes.png", "summary.json"):
        assert (folder / name).is_file(), name
    header = (folder / "history.csv").read_text().splitlines()[0].split(",")
    assert sum(h[0] == "u" and h[1:-2].isdigit() and h.endswith("_m") for h in header) == 9
    assert sum(h.startswith("theta") for h in header) == 8


def test_engine_settings_are_the_scoped_ones():
    """The scoping values of docs/engine.md; a change must be deliberate."""
    s = EngineSettings()
    assert (s.time_step, s.solver_iterations, s.erp, s.friction) == (1e-4, 100, 0.2, 1.0)
    assert dataclasses.replace(s, friction=0.5).friction == 0.5


def test_engine_domain_plot_marks_the_engine_uplift_level():
    """The sweep's domain figure of an engine config draws the engine's own uplift
    level (true solid: tan(alpha) g, 0.219 g for the paper's column), not the RBM's
    static multiplier (0.192 g): guards the plot the sweep and `rbm plot-domain` save."""
    import matplotlib.pyplot as plt
    import pandas as pd

    from rbm_cli.report.domain_figure import domain_figure

    cfg = config(TAPER)
    df = pd.DataFrame(
        {"amplitude_g": [0.1, 0.5], "frequency_hz": [1.0, 1.0], "status": ["survived"] * 2}
    )
    fig = domain_figure(df, cfg)
    (line,) = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == "static"]
    level = math.tan(stack_slenderness(drum_solids(cfg.column))[0])
    assert line.get_ydata()[0] == pytest.approx(level, rel=1e-12)
    assert line.get_ydata()[0] == pytest.approx(0.219, abs=5e-4)
    assert line.get_label().startswith("engine uplift level")
    plt.close(fig)


def _frame(tilts):
    """A two-drum stack at rest with the given in-plane tilts [rad]."""
    rot = np.array(
        [[[math.cos(t), 0, math.sin(t)], [0, 1, 0], [-math.sin(t), 0, math.cos(t)]] for t in tilts]
    )
    n = len(tilts)
    return Frame(
        np.zeros((n, 3)), rot, np.zeros(n), np.zeros(n), np.zeros((n, 3)), np.zeros((n, 3))
    )


def _two_drums():
    masses = np.array([3.0, 2.0])
    return StackGeometry(
        masses, np.ones(2), np.ones(2), np.ones(2), np.array([math.inf, 1.0]), np.array([5.0, 2.0])
    )


@pytest.mark.parametrize("mu, theta", [(1.0, 0.05), (10.0, 0.01), (0.3, -0.02)])
def test_friction_demand_of_an_open_joint_takes_the_admissible_normals(mu, theta):
    """With no change of momentum the mean force on each joint is M (a_g, 0, g), at
    psi = atan(a_g / g) from the vertical. Drum 2 turned by theta on drum 1 (open
    joint, corner on corner): every normal between the two faces is admissible,
    so a force on the edge of the Coulomb cone about drum 2's face reads mu, not
    tan(atan(mu) + theta) (the support's face alone: 11.1 for mu 10, theta 0.01);
    a force between the two normals needs no friction; a seated joint and the
    ground (one normal each) read tan(psi - phi)."""
    stack = _two_drums()
    psi = theta + math.copysign(math.atan(mu), theta)  # beyond drum 2's normal
    a_g = G * math.tan(psi)
    open_ = _frame([0.0, theta])
    demand = joint_friction(open_, open_, stack, 0.01, a_g)
    assert demand[1] == pytest.approx(mu, rel=1e-12)
    assert demand[0] == pytest.approx(abs(math.tan(psi)), rel=1e-12)  # the ground's normal
    assert abs(math.tan(psi)) > mu * (1 + abs(theta))  # the support's face alone: above mu
    between = joint_friction(open_, open_, stack, 0.01, G * math.tan(0.5 * theta))
    assert between[1] == 0.0
    seated = _frame([theta, theta])  # both drums turned alike: one normal, at theta
    demand = joint_friction(seated, seated, stack, 0.01, a_g)
    assert demand[1] == pytest.approx(mu, rel=1e-12)
    assert demand[0] == pytest.approx(abs(math.tan(psi)), rel=1e-12)  # tilted base, flat ground
    # the faces' range over the interval widens the admissible normals
    flat = _frame([0.0, 0.0])
    assert joint_friction(flat, flat, stack, 0.01, a_g)[1] == pytest.approx(abs(math.tan(psi)))
    span = (np.array([0.0, min(0.0, theta)]), np.array([0.0, max(0.0, theta)]))  # drum tilts
    assert joint_friction(flat, flat, stack, 0.01, a_g, span)[1] == pytest.approx(mu, rel=1e-12)
