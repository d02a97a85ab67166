"""Helpers of the tests that run the CLI in a process of its own and look at it."""

from __future__ import annotations

#: A run of minutes (8 elastic drums, 10,000 s): one to interrupt or kill.
LONG = """\
name: long
column: {height: 5.0, base_width: 0.96, top_width: 0.66, drums: 8}
interface: {stiffness: {normal: 5e9}}
excitation: {type: harmonic, duration: 10000}
solver: {max_steps: 1e9, max_events: 1e9}
"""


def parent_modules(*modules: str) -> str:
    """Python code for ``python -c CODE rbm ARGS...``: `rbm ARGS` in this interpreter; at
    exit the command's own process (not a child it forked) prints ``MODULES`` and, for
    each of ``modules``, whether it is in sys.modules (True/False)."""
    names = ", ".join(f"{m!r} in sys.modules" for m in modules)
    return f"""\
import atexit, os, sys
parent = os.getpid()
atexit.register(lambda: os.getpid() == parent and print("MODULES", {names}))
sys.argv = ["rbm", *sys.argv[1:]]
from rbm_cli.cli.main import main
main()
"""
