"""The CLI's shared pieces: the `rbm` group, one-line errors, config loading, options.

Command modules (run, domain, bench) import from here; nothing here imports them.

Each command loads a config, calls one library function and writes or prints
the result. Errors a user can cause (:class:`rbm_cli.api.errors.RbmError`, bad
options) end in one line ``Error: ...`` on stderr and exit status 2.
"""

from __future__ import annotations

import gc

import click

from rbm_cli.api import __version__
from rbm_cli.api.errors import RbmError

#: Exit status of a user error (bad input, unwritable output).
EXIT_USER_ERROR = 2
#: Exit status of a run whose integration failed (files are still written).
EXIT_RUN_FAILED = 1
#: Exit status after Ctrl-C (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130


class UserError(click.ClickException):
    """A one-line error for the user, exit status 2."""

    exit_code = EXIT_USER_ERROR


class Interrupted(click.ClickException):
    """Ctrl-C: one line saying what was kept, exit status 130."""

    exit_code = EXIT_INTERRUPTED


class RbmGroup(click.Group):
    """A click group whose usage errors are one line, like every other error, and
    whose Ctrl-C is one line too (click's own says only 'Aborted!')."""

    def resolve_command(self, ctx: click.Context, args):
        name, cmd, rest = super().resolve_command(ctx, args)
        if name not in LATE_GC:  # a command that does not call work_starts
            work_starts()
        return name, cmd, rest

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except click.UsageError as exc:
            hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
            message = " ".join(exc.format_message().split())
            raise UserError(message + hint) from None
        except KeyboardInterrupt:
            raise Interrupted("interrupted (Ctrl-C)") from None


#: Commands that turn the garbage collector back on themselves (work_starts), once their
#: imports and the kernel's load are done; cli.main turns it off as the process starts.
LATE_GC = ("sweep", "run")


def work_starts() -> None:
    """The command's imports and set-up are done: what they made is frozen out of the
    garbage collector (it lives to the end) and the collector is turned back on. Idempotent."""
    if not gc.isenabled():
        gc.freeze()
        gc.enable()


def load(config_path: str):
    """Load a config, turning every library error into a one-line CLI error."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.configs import load_config

    try:
        return load_config(config_path)
    except RbmError as exc:
        raise UserError(one_line(exc)) from None


def first_use(cfg) -> None:
    """Compile (or load) the compiled code a run of this config needs before it runs
    (rbm_cli.api.cells.compile_ahead). On a first use (not in numba's cache) the run waits
    for the compile, one note on stderr saying for what and about how long, and then answers
    with the compiled code, as every later run does; a compile another rbm process runs is
    waited for, not repeated. Nothing to do for a run in Python
    (``solver.implementation: python``) or a model without compiled code."""
    # lazy: loaded when a command runs, not for `rbm --help` (docs/architecture.md, Start-up)
    from rbm_cli.api.cells import compile_ahead

    collecting = gc.isenabled()
    gc.enable()  # a compile's garbage is collected (peak 0.46 GB instead of 0.73 GB)
    try:
        compile_ahead(cfg, notify=lambda text: click.echo(f"note: {text}", err=True))
    finally:
        if not collecting:
            gc.disable()  # work_starts then freezes what the load made, as before


def one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


# --------------------------------------------------------------------------- shared options

config_argument = click.argument("config", metavar="CONFIG.yaml", type=str)


def check_output(ctx, param, value: str) -> str:
    """--output: a folder name, not empty (-o '' once wrote into the current folder)."""
    if value is not None and not value.strip():
        raise UserError(f"--output must name a folder (e.g. out), got {value!r}")
    return value


output_option = click.option(
    "-o",
    "--output",
    "output",
    default="out",
    show_default=True,
    type=str,
    callback=check_output,
    help="Output root folder; results go to OUTPUT/<name>/.",
)


@click.group(cls=RbmGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="rbm")
def cli() -> None:
    """Seismic rocking of freestanding stone columns with the Rigid Beam Model.

    \b
    Example:
        rbm info configs/spanos_koh_slender.yaml
        rbm run configs/spanos_koh_slender.yaml --amplitude 0.5 --frequency 1
    """
