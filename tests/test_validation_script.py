"""docs/make_validation.py --quick runs and writes every section of validation.md."""

import subprocess
import sys

from tests.paths import ROOT

SCRIPT = ROOT / "docs" / "make_validation.py"
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


def test_quick_validation_report(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    text = (tmp_path / "validation.md").read_text()
    for heading in HEADINGS:
        assert heading in text, heading
    assert "could not be finished" not in text
    assert len(list((tmp_path / "figures").glob("validation_*.png"))) == 7
