"""A frame of rigid columns under a beam (config ``frame: {columns, beam_mass}``) rocked by
the reference blocks `housner` and `housner-linear`.

N identical prismatic rigid columns of mass m, semi-diagonal R and slenderness alpha carry
a rigid beam of mass m_b; with gamma = m_b / (N m), Makris and Vassiliou (2013) show that
the frame obeys Housner's equation of one column with

    p_hat^2 = p^2 (1 + 2 gamma) / (1 + 3 gamma)          (rectangular columns)

and that an impact keeps the angular momentum about the new pivots, which gives

    eta = (1 - 1.5 sin^2 alpha + 3 gamma cos 2 alpha) / (1 + 3 gamma).

Since p^2 = 3 g / (4 R) for a rectangle, the frame rocks as one free column of the same
slenderness scaled by k = (1 + 3 gamma) / (1 + 2 gamma): the oracles below are that scaled
column run by the same model, and the closed forms above written out here. No value is
copied from the package's output.
"""

from __future__ import annotations

import math

import pytest
from click.testing import CliRunner

import rbm
from rbm_cli.cli.main import cli
from rbm_cli.study.sweep import config_hash

#: The columns: square sections (depth = width), the default density [kg/m^3].
HEIGHT, WIDTH, DENSITY = 4.0, 0.8, 2700.0
#: A column's mass [kg].
MASS = DENSITY * WIDTH * WIDTH * HEIGHT
#: Columns in the frame.
N = 2
#: Acceleration of gravity [m/s^2], the value the reference blocks use.
G = 9.81
MODELS = ("housner", "housner-linear")
GAMMAS = (0.5, 1.0, 2.0)
#: Harmonic cells (amplitude [g], frequency [Hz]) over 6 s of shaking: slow ones that
#: overturn the column and the frames (some after impacts), fast ones they survive with
#: several impacts, the last one a band where the frame's weight decides the outcome.
CELLS = (
    (0.3, 0.5),
    (0.4, 1.0),
    (0.6, 1.0),
    (0.8, 1.0),
    (0.8, 1.5),
    (0.5, 2.0),
    (1.2, 1.5),
    (1.7, 2.5),
)
#: rbm info's keys of a frame.
FRAME_KEYS = (
    "frame_columns",
    "beam_mass_kg",
    "frame_gamma",
    "frame_p_rad_s",
    "frame_half_diagonal_m",
    "frame_restitution",
    "frame_static_multiplier_g",
)


def config(model="housner", *, scale=1.0, gamma=None, restitution=0.9, beam_mass=None):
    """The column (height and width times ``scale``), standing free, or in a frame of N
    columns whose beam weighs gamma N m (or ``beam_mass`` [kg])."""
    raw = {
        "name": "frame",
        "model": model,
        "column": {"height": HEIGHT * scale, "base_width": WIDTH * scale},
        "interface": {"restitution": restitution},
        "excitation": {"type": "harmonic", "duration": 6.0},
    }
    if gamma is not None:
        beam_mass = gamma * N * MASS
    if beam_mass is not None:
        raw["frame"] = {"columns": N, "beam_mass": beam_mass}
    return rbm.load_config(raw)


def scale_of(gamma: float) -> float:
    """k = (1 + 3 gamma) / (1 + 2 gamma): the free column of the frame's p_hat is the
    column scaled by k (p^2 = 3 g / (4 R) for a rectangle)."""
    return (1.0 + 3.0 * gamma) / (1.0 + 2.0 * gamma)


def half_diagonal() -> float:
    """R [m] of the column."""
    return math.hypot(WIDTH / 2.0, HEIGHT / 2.0)


def eta(gamma: float) -> float:
    """The frame's coefficient of restitution (Makris and Vassiliou, rectangles)."""
    sin2 = WIDTH**2 / (WIDTH**2 + HEIGHT**2)  # sin^2 alpha, tan alpha = B / H
    cos2a = (HEIGHT**2 - WIDTH**2) / (HEIGHT**2 + WIDTH**2)  # cos 2 alpha
    return (1.0 - 1.5 * sin2 + 3.0 * gamma * cos2a) / (1.0 + 3.0 * gamma)


def close(a: float, b: float, rel: float) -> bool:
    """a and b within ``rel`` of each other, or both NaN (a column that survived)."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return math.isclose(a, b, rel_tol=rel, abs_tol=0.0)


def assert_same_runs(frame, column) -> list[str]:
    """The frame and the column give the same run at every cell: status, collapse time and
    peak rotation ratio to 1e-8 relative (the two blocks' p differ in their last bits, so
    the integrator's steps may too), the same impacts. Returns the statuses."""
    statuses = []
    for amplitude, frequency in CELLS:
        a = rbm.run(frame, amplitude, frequency, record=False)
        b = rbm.run(column, amplitude, frequency, record=False)
        cell = (amplitude, frequency, a.status, b.status)
        assert a.status == b.status, cell
        assert close(a.t_collapse_s, b.t_collapse_s, 1e-8), (cell, a.t_collapse_s, b.t_collapse_s)
        ra, rb = a.result["max_rotation_ratio"], b.result["max_rotation_ratio"]
        assert close(ra, rb, 1e-8), (cell, ra, rb)
        assert a.result["n_impacts"] == b.result["n_impacts"], cell
        statuses.append(a.status)
    return statuses


# ------------------------------------------------------------------ similarity


@pytest.mark.parametrize("gamma", GAMMAS)
@pytest.mark.parametrize("model", MODELS)
def test_a_frame_rocks_as_its_column_scaled_by_k(model, gamma):
    """With one restitution for both, the frame's p_hat is the p of the column scaled by k
    (same slenderness), so every run is the scaled column's."""
    frame = config(model, gamma=gamma)
    column = config(model, scale=scale_of(gamma))
    statuses = assert_same_runs(frame, column)
    assert {"collapsed", "survived"} <= set(statuses), statuses  # both outcomes are tested


@pytest.mark.parametrize("gamma", GAMMAS)
@pytest.mark.parametrize("model", MODELS)
def test_housner_restitution_of_a_frame_is_eta(model, gamma):
    """`restitution: housner` on a frame is eta, not the column's own coefficient: the frame
    runs as the scaled column given eta as a number."""
    e_column = 1.0 - 1.5 * WIDTH**2 / (WIDTH**2 + HEIGHT**2)
    assert abs(eta(gamma) - e_column) > 1e-3  # the two coefficients would give other runs
    frame = config(model, gamma=gamma, restitution="housner")
    column = config(model, scale=scale_of(gamma), restitution=eta(gamma))
    assert_same_runs(frame, column)


# ------------------------------------------------------------------ a beam of no mass


def bits(value):
    """A result's value in a form that compares equal only when bit for bit the same
    (floats by their hex form, NaN included)."""
    if isinstance(value, float):
        return value.hex()
    if isinstance(value, list | tuple):
        return tuple(bits(v) for v in value)
    if isinstance(value, dict):
        return {k: bits(v) for k, v in value.items()}
    return value


@pytest.mark.parametrize("restitution", [0.9, "housner"])
@pytest.mark.parametrize("model", MODELS)
def test_a_beam_of_no_mass_leaves_the_column_to_the_bit(model, restitution):
    """gamma = 0: each factor of the frame is exactly 1, so its runs are the free column's,
    every figure but the wall time bit for bit."""
    frame = config(model, beam_mass=0.0, restitution=restitution)
    column = config(model, restitution=restitution)
    assert frame.frame is not None and column.frame is None
    for amplitude, frequency in CELLS:
        a = rbm.run(frame, amplitude, frequency, record=False).result
        b = rbm.run(column, amplitude, frequency, record=False).result
        keys = set(a) - {"wall_time_s"}
        assert keys == set(b) - {"wall_time_s"}
        for key in sorted(keys):
            assert bits(a[key]) == bits(b[key]), (amplitude, frequency, key, a[key], b[key])


# ------------------------------------------------------------------ a heavier beam


@pytest.mark.parametrize("model", MODELS)
def test_a_heavy_beam_keeps_up_a_frame_whose_columns_fall_alone(model):
    """At 2.5 Hz and 1.7 g the column alone overturns, and a frame of such columns under a
    beam of twice their mass (gamma 2) does not, at that amplitude or any lower one.

    Why: the frame rocks as the column scaled by k = 7/5, so p_hat = p sqrt(5/7) is lower;
    at a fixed ground frequency omega / p_hat is higher, and the amplitude that overturns a
    block under a harmonic rises with omega / p (Housner's size effect, Makris and
    Vassiliou's stabilising beam). At 2.5 Hz the column first overturns near 1.45 g and
    does so in a band from about 1.68 g, while the frame's lowest overturning amplitude is
    above 1.7 g in both models (1.74 g for housner-linear, 1.94 g for housner).
    """
    column, frame = config(model), config(model, gamma=2.0)
    frequency, amplitude = 2.5, 1.7
    assert rbm.run(column, amplitude, frequency, record=False).status == "collapsed"
    for tenth in range(2, 18):  # 0.2 .. 1.7 g
        a = tenth / 10.0
        assert rbm.run(frame, a, frequency, record=False).status == "survived", a


# ------------------------------------------------------------------ rbm info


@pytest.mark.parametrize("gamma", (0.0, *GAMMAS))
def test_info_gives_the_frames_closed_forms(gamma):
    beam = gamma * N * MASS
    info = rbm.info(config("housner", beam_mass=beam))
    r = half_diagonal()
    p = math.sqrt(3.0 * G / (4.0 * r))  # the column's p (rectangle)
    expected = {
        "frame_gamma": beam / (N * MASS),
        "frame_p_rad_s": p * math.sqrt((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma)),
        "frame_half_diagonal_m": scale_of(gamma) * r,
        "frame_restitution": eta(gamma),
        "frame_static_multiplier_g": WIDTH / HEIGHT,
    }
    for key, value in expected.items():
        assert math.isclose(info[key], value, rel_tol=1e-12, abs_tol=0.0), (key, info[key], value)
    assert info["frame_columns"] == N and info["beam_mass_kg"] == beam


def test_info_of_a_frame_of_cylinders_follows_the_general_forms():
    """For a shape other than a rectangle the frame's figures take the column's
    m R^2 / I_O: p_hat^2 = p^2 (1 + 2 gamma) / (1 + 4 gamma m R^2 / I_O) and
    eta = (I_O - 2 m R^2 sin^2 alpha + 4 gamma m R^2 cos 2 alpha) / (I_O + 4 gamma m R^2),
    here for solid cylinders of diameter D (I_O = m (D^2 / 16 + H^2 / 12) + m R^2)."""
    columns, beam = 3, 3000.0
    raw = {
        "name": "cylinders",
        "model": "housner",
        "column": {"height": HEIGHT, "base_width": WIDTH, "section": "circular"},
        "frame": {"columns": columns, "beam_mass": beam},
    }
    info = rbm.info(rbm.load_config(raw))
    m = DENSITY * math.pi * WIDTH**2 / 4.0 * HEIGHT
    r = half_diagonal()
    i_o = m * (WIDTH**2 / 16.0 + HEIGHT**2 / 12.0) + m * r * r
    alpha = math.atan2(WIDTH / 2.0, HEIGHT / 2.0)
    gamma = beam / (columns * m)
    p = math.sqrt(m * G * r / i_o)
    p_hat = p * math.sqrt((1.0 + 2.0 * gamma) / (1.0 + 4.0 * gamma * m * r * r / i_o))
    expected = {
        "frame_gamma": gamma,
        "frame_p_rad_s": p_hat,
        "frame_half_diagonal_m": r * p * p / p_hat**2,  # the same shape rocking with p_hat
        "frame_restitution": (
            i_o
            - 2.0 * m * r * r * math.sin(alpha) ** 2
            + 4.0 * gamma * m * r * r * math.cos(2 * alpha)
        )
        / (i_o + 4.0 * gamma * m * r * r),
        "frame_static_multiplier_g": WIDTH / HEIGHT,
    }
    for key, value in expected.items():
        assert math.isclose(info[key], value, rel_tol=1e-12, abs_tol=0.0), (key, info[key], value)


def test_info_without_a_frame_gives_none_for_its_keys():
    info = rbm.info(config("housner"))
    for key in FRAME_KEYS:
        assert key in info and info[key] is None, key


def test_rbm_info_prints_a_frame_line(tmp_path):
    text = """\
name: frame
model: housner
column: {height: 4.0, base_width: 0.8}
excitation: {type: harmonic, duration: 6.0}
"""
    lines = {}
    for name, extra in (("alone", ""), ("frame", "frame: {columns: 2, beam_mass: 1000}\n")):
        path = tmp_path / f"{name}.yaml"
        path.write_text(text + extra, encoding="utf-8")
        res = CliRunner().invoke(cli, ["info", str(path)])
        assert res.exit_code == 0, res.output
        lines[name] = [line for line in res.output.splitlines() if line.startswith("frame")]
    assert any("2 columns" in line and "1000 kg" in line for line in lines["frame"]), lines
    assert not lines["alone"], lines["alone"]


# ------------------------------------------------------------------ validation

BASE = """\
name: frame
model: {model}
column: {{height: 4.0, base_width: 0.8{column}}}
excitation: {{type: harmonic, duration: 6.0}}
frame: {frame}
"""
GOOD = "{columns: 2, beam_mass: 1000}"

# (label, model, extra column keys, the frame section's value, fragments of the message)
BAD_FRAMES = [
    ("one column", "housner", "", "{columns: 1, beam_mass: 1000}", ["frame.columns"]),
    ("columns 2.5", "housner", "", "{columns: 2.5, beam_mass: 1000}", ["frame.columns"]),
    ("columns a word", "housner", "", '{columns: "two", beam_mass: 1000}', ["frame.columns"]),
    ("columns a boolean", "housner", "", "{columns: true, beam_mass: 1000}", ["frame.columns"]),
    ("negative beam", "housner", "", "{columns: 2, beam_mass: -1}", ["frame.beam_mass"]),
    ("infinite beam", "housner", "", "{columns: 2, beam_mass: .inf}", ["frame.beam_mass"]),
    ("beam a word", "housner", "", '{columns: 2, beam_mass: "heavy"}', ["frame.beam_mass"]),
    ("frame null", "housner", "", "null", ["frame"]),
    ("unknown key", "housner", "", "{columns: 2, beam_mass: 1000, span: 3}", ["span", "frame"]),
    ("no beam mass", "housner", "", "{columns: 2}", ["frame.beam_mass"]),
    ("rbm-3d", "rbm-3d", ", section: circular", GOOD, ["frame", "rbm-3d"]),
    ("housner-3d", "housner-3d", ", section: circular", GOOD, ["frame", "housner-3d"]),
    ("tapered housner", "housner", ", top_width: 0.6", GOOD, ["column.top_width"]),
    ("tapered linear", "housner-linear", ", top_width: 0.6", GOOD, ["column.top_width"]),
]


def test_the_bad_cases_are_bad_by_their_frame_alone(tmp_path):
    """Each bad case differs from a config that is taken by the one thing it names: the
    good frame on the prismatic housner column, and each other model or column standing
    alone."""
    texts = [BASE.format(model="housner", column="", frame=GOOD)]
    for _, model, column, frame, _ in BAD_FRAMES:
        if frame == GOOD:
            alone = BASE.format(model=model, column=column, frame=GOOD)
            texts.append(alone.replace(f"frame: {GOOD}\n", ""))
    for i, text in enumerate(texts):
        path = tmp_path / f"good{i}.yaml"
        path.write_text(text, encoding="utf-8")
        res = CliRunner().invoke(cli, ["info", str(path)])
        assert res.exit_code == 0, (text, res.output)


@pytest.mark.parametrize(
    "label,model,column,frame,needles", BAD_FRAMES, ids=[case[0] for case in BAD_FRAMES]
)
def test_a_bad_frame_is_one_line_naming_the_key(tmp_path, label, model, column, frame, needles):
    path = tmp_path / "cfg.yaml"
    path.write_text(BASE.format(model=model, column=column, frame=frame), encoding="utf-8")
    res = CliRunner().invoke(cli, ["info", str(path)])
    lines = [line for line in res.output.splitlines() if line.strip()]
    assert res.exit_code == 2, res.output
    assert len(lines) == 1 and lines[0].startswith("Error"), res.output
    assert "Traceback" not in res.output
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    message = lines[0].split(f"{path}: ", 1)[-1]  # the path holds the test's name
    for needle in needles:
        assert needle in message, (needle, lines[0])


# ------------------------------------------------------------------ the config hash


def test_a_frame_is_a_setting_of_the_hash():
    """The frame changes what a run gives, so it is in the config's hash: a beam of no mass
    too (the frame is written, and says so), and each of its keys."""
    hashes = [
        config_hash(config("housner")),
        config_hash(config("housner", beam_mass=0.0)),
        config_hash(config("housner", beam_mass=1000.0)),
        config_hash(config("housner", beam_mass=2000.0)),
        config_hash(rbm.with_value(config("housner", beam_mass=1000.0), "frame.columns", 3)),
    ]
    assert len(set(hashes)) == len(hashes), hashes
    assert config_hash(config("housner", beam_mass=1000.0)) == hashes[2]  # and it is stable
