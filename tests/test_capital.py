"""A capital (column.capital) and a top mass (column.top_mass): their masses, the static
multiplier and p against hand computations written here, the refusals, and the runs of
every integrator method on a column with a capital."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rbm
from rbm_cli.base.errors import ConfigError, RbmError
from rbm_cli.config.types import G
from rbm_cli.structures.assembly import model_from_config

RHO = 2700.0
H, B = 2.0, 0.5  # a square prism, 0.5 m x 0.5 m x 2 m


def _cfg(column: dict, **top) -> rbm.Config:
    base = {"height": H, "base_width": B, "density": RHO}
    return rbm.load_config({"name": "cap", "column": {**base, **column}, **top})


def test_top_mass_static_multiplier_and_p_by_hand():
    """A rigid monolith with a point mass M at e above its top: moment equilibrium about the
    rocking edge at the onset of rocking under a uniform horizontal acceleration a g,
        (B / 2) (m + M) g = a g (m H / 2 + M (H + e)),
    and the rigid block's p^2 = W z_c / I_O about the base's axis point (the RBM's lever
    arm, no B / 2 term), I_O = m (H^2 + B^2) / 12 + m (H / 2)^2 + M (H + e)^2."""
    big_m, e = 800.0, 0.3
    m = RHO * B * B * H
    figures = rbm.info(_cfg({"top_mass": {"mass": big_m, "height_of_centre": e}}))
    a = (B / 2.0) * (m + big_m) / (m * H / 2.0 + big_m * (H + e))
    i_o = m * (H * H + B * B) / 12.0 + m * (H / 2.0) ** 2 + big_m * (H + e) ** 2
    p = math.sqrt(G * (m * H / 2.0 + big_m * (H + e)) / i_o)
    assert figures["static_multiplier_g"] == pytest.approx(a, rel=1e-12)
    assert figures["uplift_acceleration_g"] == pytest.approx(a, rel=1e-12)
    assert figures["rocking_p_rad_s"] == pytest.approx(p, rel=1e-12)
    assert figures["total_mass_kg"] == pytest.approx(m + big_m, rel=1e-12)
    # the mass lowers the multiplier below B / H and p below the bare block's
    bare = rbm.info(_cfg({}))
    assert a < bare["static_multiplier_g"] == pytest.approx(B / H)
    assert p < bare["rocking_p_rad_s"]


def test_top_mass_normal_forces_and_geometric_gravity():
    """Every joint carries the top mass's weight; the `geometric` gravity stiffness of a
    monolith is the weight times its centre's height, g (m H / 2 + M (H + e))."""
    big_m, e = 500.0, 0.2
    cfg = _cfg(
        {"drums": 2, "top_mass": {"mass": big_m, "height_of_centre": e}},
        interface={"stiffness": {"normal": 5e9}},
    )
    col = model_from_config(cfg).column
    drum = RHO * B * B * H / 2.0
    assert col.normal_forces == pytest.approx([(2 * drum + big_m) * G, (drum + big_m) * G])
    mono = model_from_config(_cfg({"top_mass": {"mass": big_m, "height_of_centre": e}},
                                  interface={"formulation": "geometric"}))  # fmt: skip
    m = RHO * B * B * H
    assert mono.gravity[0, 0] == pytest.approx(G * (m * H / 2 + big_m * (H + e)), rel=1e-12)


def test_capital_masses_multiplier_and_p_by_hand():
    """A monolithic shaft with a capital: two drums. The capital's mass is its own volume;
    the base's theta_u is (B / 2) / zbar_1 of the stack, the capital's (B_top / 2) / (h_c / 2)
    (it rocks on the shaft's top section); p is that of the two drums rigid together."""
    hc, wc, dc = 0.3, 0.7, 0.6
    cfg = _cfg({"capital": {"height": hc, "width": wc, "depth": dc}},
               interface={"stiffness": {"normal": 5e9}})  # fmt: skip
    figures = rbm.info(cfg)
    m_s, m_c = RHO * B * B * H, RHO * wc * dc * hc
    zbar = (m_s * H / 2 + m_c * (H + hc / 2)) / (m_s + m_c)
    theta = [(B / 2) / zbar, (B / 2) / (hc / 2)]
    i_o = (m_s * (H * H + B * B) / 12 + m_s * (H / 2) ** 2
           + m_c * (hc * hc + wc * wc) / 12 + m_c * (H + hc / 2) ** 2)  # fmt: skip
    p = math.sqrt((m_s + m_c) * G * zbar / i_o)
    rows = figures["interfaces"]
    assert figures["n_drums"] == 2
    assert figures["height_m"] == pytest.approx(H + hc)
    assert rows["drum_mass_kg"].tolist() == pytest.approx([m_s, m_c], rel=1e-12)
    assert rows["width_m"].tolist() == pytest.approx([B, B])  # the capital's joint: the top
    assert rows["rotation_capacity_rad"].tolist() == pytest.approx(theta, rel=1e-12)
    assert figures["static_multiplier_g"] == pytest.approx(min(theta), rel=1e-12)
    assert figures["rocking_p_rad_s"] == pytest.approx(p, rel=1e-12)
    # on a shaft tapered to 0.1 m a tall capital governs: B_top / h_c
    slim = rbm.info(_cfg({"top_width": 0.1, "capital": {"height": 1.0, "width": 0.2}},
                         interface={"stiffness": {"normal": 5e9}}))  # fmt: skip
    assert slim["static_multiplier_g"] == pytest.approx(0.1 / 1.0, rel=1e-12)


def test_circular_capital_is_a_cylinder():
    cfg = _cfg({"section": "circular", "capital": {"height": 0.4, "width": 0.8}},
               interface={"stiffness": {"normal": 5e9}})  # fmt: skip
    mass = model_from_config(cfg).column.masses[1]
    assert mass == pytest.approx(RHO * math.pi / 4 * 0.8**2 * 0.4, rel=1e-12)


@pytest.mark.parametrize(
    ("column", "top", "match"),
    [
        ({"capital": {"height": 0.0, "width": 0.5}}, {}, r"column\.capital\.height"),
        ({"capital": {"width": 0.5}}, {}, r"column\.capital\.height is required"),
        ({"capital": {"height": 0.3, "width": 0.5}}, {}, r"rigid needs a monolithic"),
        (
            {"capital": {"height": 0.3, "width": 0.5, "depth": 0.4}, "section": "circular"},
            {"interface": {"stiffness": {"normal": 5e9}}},
            r"capital\.depth applies only",
        ),
        ({"top_mass": {"mass": 0.0}}, {}, r"column\.top_mass\.mass"),
        ({"top_mass": {"mass": 10.0, "height_of_centre": -1}}, {}, r"height_of_centre"),
        ({"top_mass": {"mass": 10.0}}, {"model": "housner"}, r"model rbm only"),
        ({"capital": {"height": 0.3, "width": 0.5}}, {"model": "bullet"}, r"model rbm only"),
    ],
)
def test_bad_capital_or_top_mass_is_refused_in_one_line(column, top, match):
    """A capital of zero height is refused (not taken as no capital)."""
    with pytest.raises(ConfigError, match=match) as err:
        _cfg(column, **top)
    assert "\n" not in str(err.value)


def test_without_them_the_config_resolves_as_before():
    """No capital and no top mass: the resolved form holds their default, none."""
    column = _cfg({}).resolved()["column"]
    assert column["capital"] is None and column["top_mass"] is None
    assert (
        "capital"
        in _cfg(
            {"capital": {"height": 0.3, "width": 0.5}}, interface={"stiffness": {"normal": 5e9}}
        ).resolved()["column"]
    )


def test_size_axis_scales_the_capital_and_the_top_mass():
    from rbm_cli.config.points import point_written

    written = {"name": "s", "column": {"height": 2.0, "base_width": 0.5,
               "capital": {"height": 0.2, "width": 0.6},
               "top_mass": {"mass": 100.0, "height_of_centre": 0.1}}}  # fmt: skip
    data = point_written(written, (("column.size", 4.0),))
    assert data["column"]["capital"] == {"height": 0.4, "width": 1.2}
    assert data["column"]["top_mass"] == {"mass": 800.0, "height_of_centre": 0.2}


CAPITAL_RUN = {"capital": {"height": 0.5, "width": 0.6}}


@pytest.mark.parametrize("method", ["DOP853", "RK45", "RK23", "exact"])
def test_every_step_and_exact_method_runs_a_capital_column(method):
    """The integrators read the model's arrays: a capital column runs with each, and the
    exact and step methods agree on the outcome and the peak (a second computation)."""
    top = {"interface": {"stiffness": {"normal": 5e9}}, "solver": {"method": method},
           "excitation": {"type": "harmonic", "duration": 3.0}}  # fmt: skip
    cfg = _cfg(CAPITAL_RUN, **top)
    ref = _cfg(CAPITAL_RUN, **{**top, "solver": {"method": "DOP853"}})
    a = rbm.run(cfg, amplitude_g=0.3, frequency_hz=1.5, record=False)
    b = rbm.run(ref, amplitude_g=0.3, frequency_hz=1.5, record=False)
    assert a.status == b.status
    assert a.result.max_rotation_ratio == pytest.approx(b.result.max_rotation_ratio, rel=1e-5)


def test_closed_form_refuses_a_capital_and_takes_a_top_mass():
    top = {"interface": {"stiffness": {"normal": 5e9}}, "solver": {"method": "closed-form"}}
    with pytest.raises(RbmError, match="closed-form: it takes a rigid monolithic") as err:
        rbm.run(_cfg(CAPITAL_RUN, **top), amplitude_g=0.3, frequency_hz=1.5)
    assert "\n" not in str(err.value)
    # a rigid monolith with a top mass is one drum: the closed form and DOP853 agree
    mono = {"top_mass": {"mass": 600.0, "height_of_centre": 0.2}}
    runs = [rbm.run(_cfg(mono, solver={"method": m}), amplitude_g=0.25, frequency_hz=1.0,
                    record=False) for m in ("closed-form", "DOP853")]  # fmt: skip
    assert runs[0].status == runs[1].status
    assert runs[0].result.max_rotation_ratio == pytest.approx(
        runs[1].result.max_rotation_ratio, rel=1e-5
    )


def test_top_mass_uplift_level_in_a_run():
    """The rigid monolith with a top mass stays at rest below its hand-computed static
    multiplier and rocks above it (a half-sine pulse of amplitude just below / above)."""
    big_m, e = 800.0, 0.3
    m = RHO * B * B * H
    a = (B / 2.0) * (m + big_m) / (m * H / 2.0 + big_m * (H + e))
    cfg = _cfg({"top_mass": {"mass": big_m, "height_of_centre": e}},
               excitation={"type": "half-sine", "duration": 3.0})  # fmt: skip
    below = rbm.run(cfg, amplitude_g=0.99 * a, frequency_hz=1.0, record=False)
    above = rbm.run(cfg, amplitude_g=1.05 * a, frequency_hz=1.0, record=False)
    assert np.isclose(below.result.max_rotation_ratio, 0.0)
    assert above.result.max_rotation_ratio > 0.0


def test_rbm_info_prints_them_and_refuses_a_flat_capital_in_one_line(tmp_path):
    import yaml
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    column = {"height": H, "base_width": B, "capital": {"height": 0.4, "width": 0.6},
              "top_mass": {"mass": 250.0, "height_of_centre": 0.1}}  # fmt: skip
    good = tmp_path / "good.yaml"
    good.write_text(yaml.safe_dump({"name": "c", "column": column,
                                    "interface": {"stiffness": {"normal": 5e9}}}))  # fmt: skip
    res = CliRunner().invoke(cli, ["info", str(good)])
    assert res.exit_code == 0, res.output
    assert "capital:             0.4 m high, 0.6 x 0.6 m" in res.output
    # the top mass's centre: 2 m shaft + 0.4 m capital + 0.1 m above it
    assert "top mass:            250 kg, centre at 2.5 m" in res.output
    bad = tmp_path / "bad.yaml"
    column["capital"]["height"] = 0
    bad.write_text(yaml.safe_dump({"name": "c", "column": column,
                                   "interface": {"stiffness": {"normal": 5e9}}}))  # fmt: skip
    res = CliRunner().invoke(cli, ["info", str(bad)])
    assert res.exit_code != 0
    assert len(res.output.strip().splitlines()) == 1
    assert "column.capital.height" in res.output and "Traceback" not in res.output
