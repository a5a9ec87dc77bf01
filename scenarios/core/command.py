"""How every command ends (README "What a user can expect"): one line on standard error and an exit code,
never a traceback unless ``--debug`` asks for it.

    exit 0    done
    exit 1    a run failed (an integration failure names the time, the element family and failed_state.npz)
    exit 2    a usage error: a bad argument or parameter, named with its value and what is expected
    exit 130  interrupted (Ctrl-C): finished runs and checkpoints are kept; the same command resumes
"""
from __future__ import annotations

import errno
import functools
import os
import sys

from components.units import ParameterError
from mbd.errors import IntegrationError, ModelError

from .integrity import OtherResults
from .plausibility import Implausible
from .lock import FolderLocked

__all__ = ["command", "USAGE", "FAILED", "INTERRUPTED"]

USAGE, FAILED, INTERRUPTED = 2, 1, 130


def command(main):
    """Wrap a scenario's ``main(argv) -> int`` with the exit-code and one-line-error rules above."""

    @functools.wraps(main)
    def wrapped(argv=None) -> int:
        args = list(sys.argv[1:] if argv is None else argv)
        debug = "--debug" in args
        if debug:
            args.remove("--debug")
        try:
            return int(main(args) or 0)
        except KeyboardInterrupt:
            print("interrupted: finished runs and checkpoints are kept; run the same command again to resume",
                  file=sys.stderr)
            return INTERRUPTED
        except SystemExit as exc:            # argparse's own usage errors (already printed) and our messages
            if isinstance(exc.code, str):
                print(exc.code if exc.code.startswith("error:") else f"error: {exc.code}", file=sys.stderr)
                return USAGE
            return exc.code if isinstance(exc.code, int) else 0
        except (ParameterError, ModelError, OtherResults, Implausible) as exc:
            if debug:
                raise
            print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
            return USAGE
        except IntegrationError as exc:
            if debug:
                raise
            print(f"error: the run failed: {' '.join(str(exc).split())}", file=sys.stderr)
            return FAILED
        except FolderLocked as exc:
            print(f"error: {exc}", file=sys.stderr)
            return FAILED
        except BrokenPipeError:              # the reader stopped reading (`| head`): nothing went wrong
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # so the exit's flush is quiet too
            return 0
        except OSError as exc:               # disk full, unwritable folder: earlier results are intact
            if debug:
                raise
            print(f"error: {_os_error(exc)}", file=sys.stderr)
            return FAILED
        except Exception as exc:             # a defect: say what, keep the traceback for --debug
            if debug:
                raise
            print(f"error: {type(exc).__name__}: {' '.join(str(exc).split())} (run with --debug for the traceback)",
                  file=sys.stderr)
            return FAILED

    return wrapped


_FULL = {errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)}
_DENIED = {errno.EACCES, errno.EPERM, errno.EROFS}


def _os_error(exc: OSError) -> str:
    """One line for a failed file operation: what, where, and what the user can do."""
    what = exc.strerror or " ".join(str(exc).split())
    where = f": {exc.filename}" if exc.filename else ""
    if exc.errno in _FULL:
        return (f"{what}{where}; nothing was half-written (earlier results and checkpoints are intact): free some "
                f"space and run the same command again to resume")
    if exc.errno in _DENIED:
        return f"{what}{where}; choose a folder you can write (--out)"
    return f"{what}{where}"
