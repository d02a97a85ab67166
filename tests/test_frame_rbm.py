"""The Rigid Beam Model's frame (rbm_cli.structures.frame): N columns under a beam that rests
on their tops, rocking in unison.

Checked against what holds independently of the frame's code:
- a rigid monolithic frame is the RBM's own equivalent block: with the beam's share a body
  on the top node (the RBM's small rotations move it horizontally, at H), the frame's
  equation is (I_G + m h^2 + 4 (m_b / N) h^2) theta'' = -(m + 2 m_b / N) g b sgn(theta)
  + (m + 2 m_b / N) g h theta - (m + 2 m_b / N) h a_g (h = H / 2, b = B / 2), the
  linear block of tan alpha = b / h (the free column's: its uplift and collapse whatever
  gamma) and p^2 = 6 g H (1 + 2 gamma) / (4 H^2 + B^2 + 12 gamma H^2) for a rectangle.
  The free RBM column's p^2 = 6 g H / (4 H^2 + B^2) falls as 1 / size at a fixed shape,
  so the frame rocks as the free column scaled by k = p^2 / p_frame^2 (Makris and
  Vassiliou's exact frame has k = (1 + 3 gamma) / (1 + 2 gamma) instead: the RBM puts the
  beam at the top node, not at the column's far corner): checked cell by cell, in the
  closed form and in the step integrator;
- ``restitution: housner`` on a rectangular monolith is Makris and Vassiliou's eta, since
  the RBM's corner inertia of a rectangle is the true block's (4/3 m R^2);
- a beam of no mass is the free column, to the bit, rigid or of drums;
- a frame of drums: the energy balance closes (the ground's work less the impacts' loss
  is the energy kept, each term computed on its own, the beam's motion and its joint's
  law in every term); a beam moving with the ground carries a friction demand of a_g / g
  on its joint; very stiff joints rock as the rigid monolithic frame;
- what the frame cannot take is refused in one line.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from click.testing import CliRunner

from rbm_cli.api import info as rbm_info
from rbm_cli.api import load_config, run
from rbm_cli.cli.main import cli
from rbm_cli.structures.assembly import model_from_config
from rbm_cli.study.domain import read_domain

from .paths import RESULTS

G = 9.81
H, B, RHO = 4.0, 0.8, 2700.0
M = RHO * B * B * H  # a square column's mass [kg]
#: Harmonic cells (amplitude [g], frequency [Hz]) around a slender column's boundary.
CELLS = [(0.25, 0.5), (0.3, 0.8), (0.4, 1.0), (0.6, 1.5), (0.8, 2.5), (1.2, 3.0), (0.5, 0.6),
         (0.9, 1.2)]  # fmt: skip


def _monolith(gamma=None, size=1.0, restitution=0.9, method="auto", **extra):
    cfg = {
        "name": "frame",
        "model": "rbm",
        "column": {"height": H * size, "base_width": B * size},
        "interface": {"restitution": restitution},
        "excitation": {"type": "harmonic", "duration": 6.0},
        # the step integrator at rtol 1e-12: two runs on other time scales agree to 1e-8
        "solver": {"method": method} if method == "auto" else {"method": method, "rtol": 1e-12},
        **extra,
    }
    if gamma is not None:
        cfg["frame"] = {"columns": 2, "beam_mass": 2 * M * gamma}
    return load_config(cfg)


def _scale(gamma: float) -> float:
    """k = p^2 / p_frame^2 of a rectangular RBM monolith under a beam of ratio gamma."""
    return (4 * H * H + B * B + 12 * gamma * H * H) / ((1 + 2 * gamma) * (4 * H * H + B * B))


def _same_rocking(a, b):
    assert a.status == b.status
    if a.status == "collapsed":
        assert a.t_collapse_s == pytest.approx(b.t_collapse_s, rel=1e-8)
    ra, rb = a.result, b.result
    assert ra["max_rotation_ratio"] == pytest.approx(rb["max_rotation_ratio"], rel=1e-8)
    assert ra["n_impacts"] == rb["n_impacts"] and ra["n_uplifts"] == rb["n_uplifts"]


@pytest.mark.parametrize("gamma", [0.5, 1.0, 2.0])
@pytest.mark.parametrize("method", ["auto", "DOP853"])
def test_a_rigid_monolithic_frame_is_the_rbm_equivalent_block(gamma, method):
    frame = _monolith(gamma, method=method)
    block = _monolith(size=_scale(gamma), method=method)
    outcomes = set()
    for amplitude, frequency in CELLS:
        a, b = run(frame, amplitude, frequency), run(block, amplitude, frequency)
        _same_rocking(a, b)
        outcomes.add(a.status)
        assert a.result["method"] == ("closed-form" if method == "auto" else "DOP853")
    assert outcomes == {"collapsed", "survived"}


def test_the_frame_lifts_at_the_free_columns_level_whatever_gamma():
    alpha = B / H  # the RBM's tan alpha: (B / 2) / (H / 2)
    for gamma in (0.0, 0.5, 2.0):
        cfg = _monolith(gamma)
        assert rbm_info(cfg)["static_multiplier_g"] == pytest.approx(alpha, rel=1e-12)
        below = run(cfg, 0.99 * alpha, 0.5)
        above = run(cfg, 1.01 * alpha, 0.5)
        assert below.result["n_uplifts"] == 0 and below.result["max_rotation_ratio"] == 0.0
        assert above.result["n_uplifts"] > 0


@pytest.mark.parametrize("gamma", [0.5, 2.0])
def test_restitution_housner_is_the_frames_eta(gamma):
    sin2 = (B / 2) ** 2 / ((B / 2) ** 2 + (H / 2) ** 2)
    cos2a = 1.0 - 2.0 * sin2
    eta = (1.0 - 1.5 * sin2 + 3.0 * gamma * cos2a) / (1.0 + 3.0 * gamma)
    frame = _monolith(gamma, restitution="housner")
    block = _monolith(size=_scale(gamma), restitution=eta)
    for amplitude, frequency in CELLS:
        _same_rocking(run(frame, amplitude, frequency), run(block, amplitude, frequency))


def _bits(cell) -> dict:
    out = dict(cell.result)
    out.pop("wall_time_s")
    return {k: repr(v) for k, v in out.items()}


@pytest.mark.parametrize(
    "column, interface",
    [
        ({"height": H, "base_width": B}, {"restitution": 0.9}),
        ({"height": H, "base_width": B, "top_width": 0.6, "drums": 3},
         {"restitution": 0.9, "stiffness": {"normal": 5e9}, "damping": 0.02}),
    ],
)  # fmt: skip
def test_a_beam_of_no_mass_is_the_free_column_to_the_bit(column, interface):
    base = {"name": "f", "column": column, "interface": interface,
            "excitation": {"type": "harmonic", "duration": 4.0}}  # fmt: skip
    free = load_config(base)
    frame = load_config({**base, "frame": {"columns": 3, "beam_mass": 0.0}})
    for amplitude, frequency in [(0.3, 1.0), (0.6, 2.0)]:
        assert _bits(run(frame, amplitude, frequency)) == _bits(run(free, amplitude, frequency))


@pytest.mark.parametrize("method", ["auto", "DOP853"])
def test_a_monolithic_frame_rocking_carries_the_beams_inertia_to_the_ground(method):
    # at rest (0.1 g < B / H) the frame moves with the ground: T / N = a_g / g, held for
    # 0.03 s about the sine's peak: 0.1 cos(pi f 0.03); rocking, the base carries the
    # drum's and the beam share's inertia: both integrators (the closed form and the step
    # kernel's bodies) give one demand
    cfg = _monolith(1.0, method=method)
    held = 0.1 * math.cos(math.pi * 0.5 * 0.03)
    assert run(cfg, 0.1, 0.5).result["friction_demand"][0] == pytest.approx(held, rel=1e-9)
    # (the free column's two integrators differ by 1.5e-5 at this cell: the step kernel's
    # held demand samples a quintic of theta''; a beam share left out of either changes
    # the demand by percents)
    both = [run(_monolith(1.0, method=m), 0.3, 0.8).result for m in ("auto", "DOP853")]
    assert both[0]["friction_demand"][0] == pytest.approx(both[1]["friction_demand"][0],
                                                          rel=1e-4)  # fmt: skip


def test_a_rigid_monolithic_frames_beam_joint_slips_first_where_its_demand_is_higher():
    """Rocking at 0.3 g, 0.8 Hz, the beam share's held demand exceeds the base's (the top
    node accelerates twice as much as the drum's centre): with interface.friction between
    the two, the first exceedance is the beam joint's (2), at the same sample in the closed
    form, the step and the exact integrators."""
    slips = set()
    for method in ("auto", "DOP853", "exact"):
        cfg = _monolith(1.0, method=method)
        cfg = load_config({**cfg.written, "interface": {**cfg.written["interface"],
                                                        "friction": 0.24}})  # fmt: skip
        result = run(cfg, 0.3, 0.8).result
        base, beam = result["friction_demand"]
        assert base < 0.24 < beam
        slips.add(tuple(result["slip"]))
    assert len(slips) == 1 and next(iter(slips))[1] == 2


DRUMS = {"height": H, "base_width": B, "drums": 4}


def _drums(gamma, stiffness=None, **extra):
    return load_config(
        {
            "name": "colonnade",
            "model": "rbm",
            "column": DRUMS,
            "interface": {"restitution": 0.9, "stiffness": stiffness or {"normal": 5e9}},
            "excitation": {"type": "harmonic", "duration": 4.0},
            "frame": {"columns": 2, "beam_mass": 2 * M * gamma},
            **extra,
        }
    )


def test_a_frame_of_drums_closes_its_energy_balance():
    cell = run(_drums(1.0), 0.35, 1.5, record=True)
    r = cell.result
    assert r["n_uplifts"] > 5 and r["n_impacts"] > 5  # every joint's law at work
    assert len(r["friction_demand"]) == 5  # four drum joints and the beam's
    e = r["energy"]
    kept = e["final_J"] - e["initial_J"]
    balance = kept - (e["ground_work_J"] - e["damping_J"] - e["impacts_J"])
    assert e["impacts_J"] > 0 and e["ground_work_J"] > 0
    assert abs(balance) <= 1e-8 * e["ground_work_J"], e


@pytest.mark.parametrize("drums", [4, 1])
def test_a_beam_moving_with_the_ground_carries_its_acceleration_on_its_joint(drums):
    # 0.05 g at 0.25 Hz: far below uplift (B / H = 0.2 g), the joints' elastic modes far
    # above (the first at 68 Hz: the quasi-static amplification (0.25 / 68)^2 ~ 1e-5) and
    # damped (their ringing from the motion's start gone): the column and the beam move
    # with the ground, each joint's shear is its load's mass times a_g, its demand a_g / g;
    # a monolith's beam joint (its law folded into the base's) reports its own, second
    cfg = _drums(1.0, {"normal": 5e11})
    cfg = load_config({**cfg.written, "column": {**DRUMS, "drums": drums},
                       "interface": {**cfg.written["interface"], "damping": 0.2}})  # fmt: skip
    assert rbm_info(cfg)["elastic_frequencies_hz"][0] > 60.0
    demand = run(cfg, 0.05, 0.25).result["friction_demand"]
    assert len(demand) == drums + 1
    assert demand[-1] == pytest.approx(0.05, rel=1e-3)
    assert max(demand) == pytest.approx(0.05, rel=1e-3)


@pytest.mark.parametrize("method", ["auto", "DOP853", "exact"])
def test_a_rigid_monolithic_frame_at_rest_carries_a_g_on_its_beam_joint(method):
    # at rest (0.1 g < B / H) every body moves with the ground: the beam share's shear over
    # its weight is a_g / g, as the base's, held for 0.03 s about the sine's crest
    # 0.1 cos(pi f 0.03), its peak the crest, in the closed form, the step and the exact
    # integrators alike
    result = run(_monolith(1.0, method=method), 0.1, 0.5).result
    held = 0.1 * math.cos(math.pi * 0.5 * 0.03)
    assert result["method"] == ("closed-form" if method == "auto" else method)
    assert result["friction_demand"] == pytest.approx([held, held], rel=1e-9)
    assert result["friction_demand_peak"] == pytest.approx([0.1, 0.1], rel=1e-12)


@pytest.mark.parametrize("method", ["auto", "DOP853", "exact"])
def test_a_rigid_monolithic_frame_rocking_freely_peaks_on_its_beam_joint_at_impact(method):
    """Released from theta = alpha / 2 (alpha = B / H), the frame rocks as its equivalent
    block: theta'' = p^2 (theta - s alpha), p^2 = 6 g H (1 + 2 gamma) / (4 H^2 + B^2 +
    12 gamma H^2), largest, p^2 alpha, at an impact. The beam share, gamma m at the top
    node (H), carries gamma m H theta'' on its weight gamma m g: its demand peaks at
    H p^2 alpha / g = p^2 B / g; the base carries the drum's m (H / 2) theta'' too on
    (1 + gamma) m g: (1 + 2 gamma) p^2 B / (2 (1 + gamma) g)."""
    gamma = 0.5
    free = {"type": "free", "duration": 3.0, "initial": {"rotations": [0.5 * B / H]}}
    result = run(_monolith(gamma, method=method, excitation=free), 0.0, 0.0).result
    p2 = 6 * G * H * (1 + 2 * gamma) / (4 * H * H + B * B + 12 * gamma * H * H)
    assert result["n_impacts"] >= 2 and result["status"] == "survived"
    want = [(1 + 2 * gamma) * p2 * B / (2 * (1 + gamma) * G), p2 * B / G]
    assert result["friction_demand_peak"] == pytest.approx(want, rel=1e-9)


def _formulated(cfg, formulation):
    """The config with interface.formulation set."""
    interface = {**cfg.written["interface"], "formulation": formulation}
    return load_config({**cfg.written, "interface": interface})


@pytest.mark.parametrize("formulation", ["relative", "geometric"])
def test_very_stiff_joints_rock_as_the_rigid_monolithic_frame(formulation):
    # `geometric` moves the stack's P-Delta from the laws to gravity through the displaced
    # drums and the beam: a stack rocking as one body on its base feels the same moment
    stiff = _formulated(_drums(1.0, {"normal": 5e12}), formulation)
    rigid = _monolith(1.0, method="DOP853")
    agree = 0
    cells = [(0.3, 0.5), (0.6, 1.0), (0.25, 0.8), (1.0, 2.0), (0.5, 0.6)]
    for amplitude, frequency in cells:
        a, b = run(stiff, amplitude, frequency), run(rigid, amplitude, frequency)
        agree += a.status == b.status
        if a.status == b.status == "collapsed":
            assert a.t_collapse_s == pytest.approx(b.t_collapse_s, rel=2e-2)
    assert agree == len(cells)


def _frame_model(formulation, gamma=1.0):
    return model_from_config(_formulated(_drums(gamma), formulation))


def test_the_geometric_frames_gravity_is_the_second_derivative_of_its_weights_height():
    """K_g of `geometric` is minus the Hessian at theta = 0 of the weights' potential, every
    drum's weight at its centre and the beam share's at the top node, written from the
    drums' masses and heights: V = g sum_j m_j (sum_{k<j} h_k cos theta_k + c_j cos theta_j)
    + g (m_b / N) sum_k h_k cos theta_k."""
    model = _frame_model("geometric")
    col = model.column
    n = col.n
    heights, centres = col.heights, col.centres
    share = 2 * M * 1.0 / 2  # the beam's share m_b / N
    hessian = np.zeros(n)  # V is a sum of cosines of single angles: its Hessian is diagonal
    for k in range(n):
        above = sum(col.masses[j] for j in range(k + 1, n)) + share
        hessian[k] = -G * (heights[k] * above + centres[k] * col.masses[k])
    assert np.allclose(model.gravity, -np.diag(hessian), rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("joint", [0, 1, 3])
def test_a_stack_tilted_rigidly_is_as_near_collapse_in_both_formulations(joint):
    """A rigid tilt x of the drums above a joint (the others still): the relative
    formulation's collapse ratio x / (theta_u (1 + xi M_u,b / M_u)) and the geometric one's,
    the stack's overturning moment (the beam share's included) over M_u + xi M_u,b, are the
    same number, since the stack's overturning moment is N zbar x = M_u x / theta_u."""
    rel, geo = _frame_model("relative"), _frame_model("geometric")
    n = rel.n
    for x in (0.01, 0.05, 0.2):
        theta = np.zeros(n)
        theta[joint:] = x
        assert geo.collapse_ratios(theta)[joint] == pytest.approx(
            rel.collapse_ratios(theta)[joint], rel=1e-12)  # fmt: skip


def test_the_absolute_frame_reads_each_drums_rotation_and_the_beam_joint_minus_the_tops():
    model = _frame_model("absolute")
    theta = np.array([0.01, -0.02, 0.03, 0.05])
    assert model.arguments(theta).tolist() == [0.01, -0.02, 0.03, 0.05, -0.05]


@pytest.mark.parametrize("formulation", ["absolute", "geometric"])
def test_a_monolithic_frame_rocks_alike_in_every_formulation(formulation):
    """One drum: the three readings of the law are one rotation (the base's, and the beam
    joint's minus it), so a rigid monolithic frame rocks alike in all three."""
    for amplitude, frequency in CELLS[:4]:
        a = run(_monolith(1.0, method="DOP853"), amplitude, frequency)
        other = _monolith(1.0, method="DOP853", interface={"restitution": 0.9,
                                                           "formulation": formulation})  # fmt: skip
        _same_rocking(a, run(other, amplitude, frequency))


def _rbm_run(tmp_path, cfg, *more):
    """`rbm run` of the config cfg (written as tmp_path/c.yaml) at 0.3 g, 1 Hz."""
    import yaml

    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return CliRunner().invoke(cli, ["run", str(path), "-a", "0.3", "-f", "1.0", *more])


@pytest.mark.parametrize("formulation", ["absolute", "geometric"])
def test_a_frame_of_drums_runs_in_every_formulation_through_the_cli(tmp_path, formulation):
    cfg = {"name": "c", "model": "rbm", "column": DRUMS,
           "interface": {"stiffness": {"normal": 5e9}, "formulation": formulation},
           "frame": {"columns": 2, "beam_mass": 2 * M}}  # fmt: skip
    res = _rbm_run(tmp_path, cfg, "-o", str(tmp_path / "out"))
    assert res.exit_code == 0, res.output
    assert (tmp_path / "out" / "c" / "run_A0.3_f1" / "summary.json").is_file()


def test_the_stored_colonnade_band_without_a_beam_is_the_stored_column():
    """The CI band of the stored colonnade holds the column alone (beam_mass 0) beside the
    beams: on every cell both stored ensembles call robust, its outcome is the stored
    8-drum study's (results/harmonic_multidrum, the same column and cells, swept from its
    own config)."""
    band = read_domain(RESULTS / "colonnade_harmonic_ci" / "domain.csv")
    alone = band[band["frame.beam_mass"] == 0.0]
    column = read_domain(RESULTS / "harmonic_multidrum" / "domain.csv")
    cells = ["amplitude_g", "frequency_hz"]
    both = alone.merge(column, on=cells, suffixes=("_band", "_column"))
    assert len(both) == len(alone) == 36
    robust = both[(both["robust_band"] == 1) & (both["robust_column"] == 1)]
    assert len(robust) >= len(alone) // 2  # the band is the chaotic one: 20 of its 36
    assert (robust["status_band"] == robust["status_column"]).all()


@pytest.mark.parametrize(
    "extra, says",
    [
        ({"interface": {"stiffness": {"rotational": [1e9, 1e9, 1e9, 1e9]}}},
         "interface.stiffness.rotational"),
        ({"column": {**DRUMS, "top_mass": {"mass": 100.0}},
          "interface": {"stiffness": {"normal": 5e9}}}, "column.top_mass and frame"),
    ],
)  # fmt: skip
def test_what_an_rbm_frame_cannot_take_is_refused_in_one_line(tmp_path, extra, says):
    cfg = {"name": "c", "model": "rbm", "column": DRUMS,
           "frame": {"columns": 2, "beam_mass": 1000.0}, **extra}  # fmt: skip
    res = _rbm_run(tmp_path, cfg)
    lines = res.output.strip().splitlines()
    assert res.exit_code == 2 and len(lines) == 1 and says in lines[0], res.output
    assert "Traceback" not in res.output


def test_a_list_of_stiffnesses_takes_the_beam_joints_last():
    cfg = _drums(1.0, {"rotational": [2e9, 2e9, 2e9, 2e9, 1e9]})
    assert rbm_info(cfg)["interfaces"]["stiffness_Nm_per_rad"].tolist()[-1] == 1e9


def test_info_gives_the_frames_rbm_figures():
    figures = rbm_info(_monolith(1.0))
    # the RBM's equivalent block: p^2 = 6 g H (1 + 2 gamma) / (4 H^2 + B^2 + 12 gamma H^2)
    p2 = 6 * G * H * 3.0 / (4 * H * H + B * B + 12 * H * H)
    assert figures["rocking_p_rad_s"] == pytest.approx(math.sqrt(p2), rel=1e-12)
