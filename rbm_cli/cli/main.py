"""Command line of rbm: thin click commands over the library.

Each command loads a config, calls one library function and writes or prints
the result. Errors a user can cause (:class:`rbm_cli.base.errors.RbmError`, bad
options) end in one line ``Error: ...`` on stderr and exit status 2.

The group and its shared helpers are in :mod:`rbm_cli.cli.common`; each command
module registers its commands on it when imported here.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")  # the CLI saves figures to files; only the CLI picks a backend

from rbm_cli.cli import bench, domain, fragility, run  # noqa: E402, F401  (register the commands)
from rbm_cli.cli.common import cli  # noqa: E402

__all__ = ["cli", "main"]


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point (``rbm``)."""
    cli.main(args=argv, prog_name="rbm")


if __name__ == "__main__":  # pragma: no cover
    main()
