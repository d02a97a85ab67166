"""What a stored result depends on, recorded in its meta.json.

rbm's arithmetic gives the same bits on every x86-64 machine (rbm_cli.base.detmath),
but a result also depends on the code and the libraries that ran it; a reader
of a stored domain must be able to tell what made it.
"""

from __future__ import annotations

import os
import platform
import subprocess
from functools import lru_cache
from pathlib import Path

import numpy

import rbm_cli
from rbm_cli import __version__
from rbm_cli.study.robustness import RULE

#: The checkout holding the package (the folder above rbm_cli/), where .git would be.
_ROOT = Path(rbm_cli.__file__).resolve().parents[1]


def _git_commit() -> str | None:
    """The checkout's commit (with '-dirty' if it has uncommitted changes), or None
    outside a git checkout (an installed wheel)."""
    if not (_ROOT / ".git").exists():
        return None
    try:
        head = subprocess.run(
            ["git", "-C", str(_ROOT), "rev-parse", "HEAD"],
            capture_output=True, text=True, timeout=5, check=True,
        ).stdout.strip()  # fmt: skip
        dirty = subprocess.run(
            ["git", "-C", str(_ROOT), "status", "--porcelain", "--untracked-files=no", "--",
             "rbm_cli"],
            capture_output=True, text=True, timeout=5, check=True,
        ).stdout.strip()  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("-dirty" if dirty else "")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _numba_target() -> str:
    """The CPU name numba compiles for (NUMBA_CPU_NAME, else the host's)."""
    # lazy: llvmlite loads only where needed (docs/architecture.md, Start-up)
    import llvmlite.binding as llvm

    return os.environ.get("NUMBA_CPU_NAME") or llvm.get_host_cpu_name()


@lru_cache(maxsize=1)
def provenance() -> dict:
    """rbm's version and commit, Python and the numerical libraries, the CPU and
    numba's target, and the robustness rule (rbm_cli.study.robustness)."""
    # lazy: llvmlite loads only where needed (docs/architecture.md, Start-up)
    import llvmlite

    # lazy: numba loads only where needed (docs/architecture.md, Start-up)
    import numba

    # lazy: scipy loads only where needed (docs/architecture.md, Start-up)
    import scipy

    libc = platform.libc_ver()
    return {
        "rbm": __version__,
        "git_commit": _git_commit(),
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "llvmlite": llvmlite.__version__,
        "platform": platform.platform(),
        "libc": " ".join(x for x in libc if x) or None,
        "cpu_model": _cpu_model(),
        "numba_target": _numba_target(),
        "arithmetic": "deterministic (rbm_cli.base.detmath): no BLAS/LAPACK or libm sin/asin "
        "in the step kernel's compiled path",
        "robustness_rule": RULE,
    }


__all__ = ["provenance"]
