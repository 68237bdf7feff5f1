"""Output files: checked before the work, never overwritten silently, never left half written.

- :func:`check_new_file`: fail *before* a run or an export when its output
  cannot be created (it exists without ``force``, is a directory, a file
  stands where a folder is needed);
- :func:`check_writable`: the same for outputs that may be overwritten, in a folder that must exist;
- :func:`unique_path`: a free default name (``run-2.mcap``, ...);
- :func:`atomic_write`: write through a temporary file in the same folder,
  flushed to disk and renamed over the target at the end; on any failure or
  interruption the temporary file is removed and the target is untouched.

- :func:`check_not_input`: an output is never one of the command's inputs
  (the log it reads, the scenario, its input files), even with ``--force``.

MCAP logs are the exception: a run streams into its log, so that a killed
process leaves the part written so far (see :mod:`cosim.log.writer`); it is
written under a temporary name until the time stepping starts, so a run that
never starts leaves nothing (:func:`cosim.run.logged.run_logged`).
"""
from __future__ import annotations

import contextlib
import os
import secrets
from collections.abc import Iterator, Sequence
from pathlib import Path

from cosim.errors import CosimError


def check_new_file(path: Path, what: str, force: bool = False) -> None:
    """Fail before any work when ``path`` cannot be created: it exists (without ``force``), is a
    directory, or a file stands where a folder is needed. Missing folders are created later."""
    if path.is_dir():
        raise CosimError(f"{path}: is a directory, expected a file name for the {what}")
    if path.exists() and not force:
        raise CosimError(f"{path}: already exists; refusing to overwrite the {what} (use --force)")
    blocking = next((folder for folder in reversed(path.parents) if folder.exists() and not folder.is_dir()), None)
    if blocking is not None:
        raise CosimError(f"{path}: cannot create the folder for the {what}: {str(blocking)!r} is a file")


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether two paths name the same file (through links too), existing or not."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (yet): compare where they would be
        return Path(a).resolve() == Path(b).resolve()


def check_not_input(output: str | os.PathLike[str], what: str, inputs: Sequence[tuple[str, Path]]) -> None:
    """Fail when an output of a command is one of its inputs, which even ``--force`` must not replace.

    Args:
        output: the file the command would write; what: which output (for the message).
        inputs: (what it is, path) of everything the command reads: the log, the scenario, its input files.

    Raises:
        CosimError: ``output`` is one of ``inputs``.
    """
    for role, path in inputs:
        if same_file(output, path):
            raise CosimError(f"{output}: is {role} of this command; refusing to write the {what} over it "
                             "(even with --force): choose another file name")


def unique_path(path: Path) -> Path:
    """``path``, or ``<stem>-2<suffix>``, ``-3``, ... if it exists (for default names)."""
    if not path.exists():
        return path
    for n in range(2, 10_000):
        candidate = path.with_name(f"{path.stem}-{n}{path.suffix}")
        if not candidate.exists():
            return candidate
    raise CosimError(f"{path}: too many runs with this name in the same second")


def check_writable(path: str | os.PathLike[str], what: str, suffixes: Sequence[str] | None = None,
                   force: bool = False) -> None:
    """Fail before the work when an output file in an existing folder cannot be written: ``path`` is a
    directory, exists (without ``force``), its folder does not exist, or its suffix is not one of
    ``suffixes`` (e.g. figure formats). For the summaries and figures of ``cosim modes`` and a static
    ``cosim run``, whose folder is not created."""
    target = Path(path)
    if target.is_dir():
        raise CosimError(f"{path}: is a directory, expected a file name for the {what}")
    if target.exists() and not force:
        raise CosimError(f"{path}: already exists; refusing to overwrite the {what} (use --force)")
    parent = target.parent
    if not parent.is_dir():
        raise CosimError(f"{path}: cannot write the {what}: directory {str(parent)!r} does not exist")
    if suffixes is not None and target.suffix.lower().lstrip(".") not in suffixes:
        raise CosimError(
            f"{path}: unsupported file type for the {what} (expected one of: "
            + ", ".join("." + s for s in suffixes) + ")"
        )


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], what: str) -> Iterator[Path]:
    """Write ``path`` through a temporary file: ``with atomic_write(out, "CSV") as tmp: <write tmp>``.

    The temporary file sits in the same folder (created if missing) with the
    same suffix (so writers that choose a format by suffix still work). When
    the block ends normally the file is flushed to disk (fsync) and renamed
    over ``path`` in one step; when it raises (or is interrupted) the
    temporary file is removed and ``path`` is left as it was.

    Raises:
        CosimError: the folder, the temporary file or the rename fails (``what`` names the output).
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CosimError(f"{path}: cannot write the {what} ({exc.strerror or exc})") from None
    partial = path.with_name(f".{path.stem}.{secrets.token_hex(4)}.part{path.suffix}")
    try:
        yield partial
        try:
            fd = os.open(partial, os.O_RDONLY)
        except FileNotFoundError:
            raise CosimError(f"{path}: cannot write the {what} (nothing was written)") from None
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(partial, path)
    except OSError as exc:
        raise CosimError(f"{path}: cannot write the {what} ({exc.strerror or exc})") from None
    except CosimError as exc:  # a writer's own message: it names the temporary file, the user gave ``path``
        raise CosimError(str(exc).replace(str(partial), str(path))) from None
    finally:
        with contextlib.suppress(OSError):
            partial.unlink(missing_ok=True)
