"""Atomic file output: a file is either absent or complete, never half-written.

A write that fails (a full disk, a folder that became unwritable) leaves the earlier file as it was
and is one ``StorageError`` naming the file and the problem (exit 1: the run failed).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

from hlp_drake.errors import HlpError, StorageError


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success move it into place, on error delete it.

    Raises:
        StorageError: ``path``'s folder cannot be made or written, writing the temporary file
            failed (an ``OSError`` in the block, e.g. a full disk), or ``path`` cannot be replaced.
    """
    target = Path(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as error:
        raise StorageError(f"{target}: cannot write: {_reason(error)}") from None
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        try:
            yield tmp
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes files private; give them the usual mode
            os.replace(tmp, target)
        except OSError as error:
            raise StorageError(f"{target}: cannot write: {_reason(error, tmp)}") from None
    finally:
        tmp.unlink(missing_ok=True)


def check_writable(*paths: str | os.PathLike[str] | None) -> None:
    """Refuse now the outputs a command could not write at its end (None: not asked for): a path
    that is a folder, or a folder that cannot be made or written (probed with a temporary file in
    the nearest existing one, removed at once; nothing is created), so no work is lost to them and
    no output is written while another is refused.

    Raises:
        HlpError: one line per output that cannot be written.
    """
    problems, refused = [], set()
    for path in paths:
        if path is None:
            continue
        target = Path(path)
        if target.is_dir():
            problems.append(f"{target}: cannot write: it is a directory")
            continue
        folder = target.parent
        while not folder.exists() and folder != folder.parent:
            folder = folder.parent
        if folder in refused:  # one line for the outputs of a folder that cannot take any
            continue
        try:
            if not folder.is_dir():
                raise NotADirectoryError(0, "not a directory", str(folder))
            fd, probe = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=folder)
        except OSError as error:
            problems.append(f"{target}: cannot write: {_reason(error)}")
            refused.add(folder)
            continue
        os.close(fd)
        os.unlink(probe)
    if problems:
        raise HlpError(*problems)


def _reason(error: OSError, written: Path | None = None) -> str:
    """``error`` in a few words, naming the path it is about (e.g. a parent that is a file) unless
    that is ``written``, the temporary file standing for the target."""
    if isinstance(error, FileExistsError | NotADirectoryError):
        return f"{error.filename} is not a directory"
    if error.filename and (written is None or Path(error.filename) != written):
        return f"{error.strerror or error} ({error.filename})"
    return str(error.strerror or error)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
