"""tools/make_validation.py --quick runs, writes every section of validation.md, and the
numbers it writes agree with closed forms computed here (not with the script's own code).

The closed forms used, for the slender block of the report (rectangle H = 4 m, B = 1 m):
- the RBM mapping (rigid monolith as linear block): alpha = B/H,
  p^2 = m g (H/2) / (I_G + m H^2/4) with I_G = m (H^2 + B^2) / 12, i.e. p^2 = 6 g H / (4 H^2 + B^2);
- Housner's block: alpha = atan(B/H), p^2 = m g R / I_O = 3 g / (4 R), R = sqrt(H^2 + B^2)/2;
- the free-rocking period of the linear equation T = (4/p) arccosh(1 / (1 - theta0/alpha));
- Housner's half-sine threshold A/alpha = sqrt(1 + (w/p)^2).
"""

import math
import subprocess
import sys

import pytest

from tests.paths import TOOLS

pytestmark = pytest.mark.slow

SCRIPT = TOOLS / "make_validation.py"
HEADINGS = (
    "# Validation report",
    "## 1. RBM n = 1 vs the closed-form linear solution",
    "### 1a. Time histories",
    "### 1b. The whole domain",
    "## 2. housner vs housner-linear as alpha grows",
    "## 3. Half-sine study vs Housner's approximation and the exact linear threshold",
    "## 4. Free-rocking period",
    "## 5. Multi-drum column in the three formulations",
    "### 5a. Energy in free motion",
    "### 5b. The paper's 8-drum column, three formulations",
)
G = 9.81  # [m/s^2], as the library
H, B = 4.0, 1.0  # the slender block [m]
P_RBM = math.sqrt(6 * G * H / (4 * H**2 + B**2))  # [rad/s]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("validation")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return out


def section(text: str, heading: str) -> str:
    """The text of a section, from its heading to the next heading of its level."""
    level = heading.split()[0]
    body = text.split(heading, 1)[1]
    ends = [body.find(f"\n{level} ")] + [body.find(f"\n{'#' * k} ") for k in range(1, len(level))]
    ends = [e for e in ends if e >= 0]
    return body[: min(ends)] if ends else body


def table(text: str, first: str) -> list[dict]:
    """Rows of the markdown table whose first header cell is `first`, as dicts."""
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith(f"| {first} |"))
    header = [c.strip() for c in lines[start].strip("|").split(" | ")]
    rows = []
    for ln in lines[start + 2 :]:
        if not ln.startswith("|"):
            break
        rows.append(dict(zip(header, (c.strip() for c in ln.strip("|").split(" | ")), strict=True)))
    return rows


def test_quick_validation_report(report):
    text = (report / "validation.md").read_text()
    for heading in HEADINGS:
        assert heading in text, heading
    assert "could not be finished" not in text
    assert len(list((report / "figures").glob("validation_*.png"))) == 7


def test_section1_mapping_and_histories_match_the_closed_form(report):
    text = section((report / "validation.md").read_text(), "## 1. RBM n = 1")
    assert f"alpha = B/H = {B / H:.6g} rad" in text
    assert f"= {P_RBM:.6g} rad/s" in text
    rows = table(text, "case")
    assert len(rows) == 2
    for row in rows:
        assert row["RBM"] == row["closed form"], row
        assert row["RBM t_collapse [s]"] == row["closed t_collapse [s]"], row
        rbm_impacts, closed_impacts = row["impacts RBM / closed"].split(" / ")
        assert rbm_impacts == closed_impacts, row
        assert float(row["max |error| / alpha"]) < 1e-5, row
    assert "cells that differ: **0** of 52" in text  # every 3rd cell: none at the boundary


def test_section2_blocks_have_housners_geometry(report):
    rows = table(section((report / "validation.md").read_text(), "## 2. "), "H/B")
    assert [row["H/B"] for row in rows] == ["10", "4", "2"]
    for row in rows:
        b = H / float(row["H/B"])
        radius = math.hypot(H, b) / 2
        assert float(row["alpha [rad]"]) == pytest.approx(math.atan(b / H), abs=5e-5)
        assert float(row["p [rad/s]"]) == pytest.approx(math.sqrt(0.75 * G / radius), abs=5e-5)


def test_section3_housner_curve_and_brackets(report):
    rows = table(section((report / "validation.md").read_text(), "## 3. "), "f [Hz]")
    assert len(rows) == 30
    # Housner's threshold over sqrt(1 + (w/p)^2) is alpha, the same at every frequency
    alphas = [float(r["Housner [g]"]) / math.hypot(1, float(r["w/p"])) for r in rows]
    assert max(alphas) - min(alphas) < 2e-4
    for r in rows:
        assert float(r["highest safe [g]"]) < float(r["lowest unsafe [g]"]), r
        exact = float(r["exact linear [g]"])
        assert exact <= float(r["Housner [g]"]), r  # Housner's approximation is too high
        in_bracket = float(r["highest safe [g]"]) < exact <= float(r["lowest unsafe [g]"])
        assert r["exact in (safe, unsafe]"] == ("yes" if in_bracket else "**no**"), r


def test_section4_periods_are_the_closed_form(report):
    rows = table(section((report / "validation.md").read_text(), "## 4. "), "theta0/alpha")
    assert [r["theta0/alpha"] for r in rows] == ["0.1", "0.5", "0.9"]
    for r in rows:
        period = 4 / P_RBM * math.acosh(1 / (1 - float(r["theta0/alpha"])))
        assert float(r["closed-form T [s]"]) == pytest.approx(period, abs=1e-9)
        assert float(r["housner_linear T [s]"]) == pytest.approx(period, abs=1e-9)
        assert float(r["RBM T [s]"]) == pytest.approx(period, rel=1e-6)
        assert int(r["RBM impacts"]) == 8  # two impacts a period over ~4.2 periods


def test_section5_energy_and_domains(report):
    text = section((report / "validation.md").read_text(), "## 5. ")
    energy = {r["formulation"]: r for r in table(text, "formulation")}
    for form in ("relative", "geometric"):  # conservative: energy kept to the tolerance
        assert float(energy[form]["max |E/E0 - 1|"]) < 1e-6
    assert float(energy["absolute"]["max |E/E0 - 1|"]) > 1e-2  # not conservative
    assert len({r["E0 [J]"] for r in energy.values()}) == 1  # same initial state
    pairs = table(text, "pair")
    assert [p["cells that differ"].split(" / ")[1] for p in pairs] == ["9"] * 3
