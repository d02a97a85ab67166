"""Command line of rbm: thin click commands over the library.

Each command loads a config, calls one library function and writes or prints
the result. Errors a user can cause (:class:`rbm_cli.api.errors.RbmError`, bad
options) end in one line ``Error: ...`` on stderr and exit status 2.

The group and its shared helpers are in :mod:`rbm_cli.cli.common`; each command
module registers its commands on it when imported here.
"""

from __future__ import annotations

import os
import signal
import sys

from rbm_cli.cli import bench, domain, fragility, run, sweep  # noqa: F401  (register the commands)
from rbm_cli.cli.common import EXIT_INTERRUPTED, cli

if "matplotlib" in sys.modules:  # (main() called from a program that drew already)
    sys.modules["matplotlib"].use("Agg")
else:  # the CLI saves figures to files; only the CLI picks a backend; matplotlib is
    os.environ["MPLBACKEND"] = "Agg"  # imported by the commands that draw, not here

__all__ = ["cli", "main"]


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point (``rbm``): the process ends with it, so what it holds is
    frozen out of the garbage collector first, and the exit does not traverse it (a
    sweep's ~200,000 objects: ~0.2-0.4 s of its wall time). The collector is
    off while the command imports and loads (collections of the young objects of module
    imports, which all live to the end: ~10 % of the start-up's CPU) and on again, with
    what was loaded frozen, once its work starts (rbm_cli.cli.common.work_starts)."""
    import gc

    gc.disable()  # until the command's work starts (common.work_starts): ~10 % of start-up
    try:
        cli.main(args=argv, prog_name="rbm")
    except SystemExit as end:
        if end.code == EXIT_INTERRUPTED:  # Ctrl-C, said in one line: the process ends with
            # 130, and a Ctrl-C still pending (one held back while files were moved,
            # rbm_cli.base.folder.signals_held) or pressed again must not end it by SIGINT
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        raise
    except KeyboardInterrupt:  # one that reached here while the command said its line
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        raise SystemExit(EXIT_INTERRUPTED) from None
    finally:
        gc.freeze()


if __name__ == "__main__":  # pragma: no cover
    main()
