"""Output paths: checked before any work, written atomically (a file is either absent or complete).

What an output may be, for every command: a regular file or a new one in an existing folder; a
symbolic link is written through (its target replaced atomically, the link kept); ``-`` is standard
output (a file output only: ``./-`` names a file called ``-``). Refused: a path that exists and is
not a regular file (a folder, a device, a named pipe, a socket), left untouched; a missing folder,
which is never created (a command's output folder, ``check_folder``, is made, its parent must exist).

A write that fails (a full disk, a folder that became unwritable) leaves the earlier file as it was
and is one ``StorageError`` naming the file and the problem (exit 1: the run failed).
"""

from __future__ import annotations

import contextlib
import os
import stat
import sys
import tempfile
from collections.abc import Iterator
from contextvars import ContextVar
from pathlib import Path
from typing import TextIO

from hlp_drake.errors import HlpError, StorageError

STDOUT = "-"
"""The output path that means standard output."""

_KINDS = {
    stat.S_IFDIR: "a directory",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFIFO: "a named pipe",
    stat.S_IFSOCK: "a socket",
}

_CLAIMED: ContextVar[list[TextIO] | None] = ContextVar("claimed_stdout", default=None)
"""Within ``output_streams``: the real standard output once an output ``-`` claimed it, else empty."""


def is_stdout(path: str | os.PathLike[str]) -> bool:
    """Whether the output ``path`` is standard output (``-``)."""
    return os.fspath(path) == STDOUT


@contextlib.contextmanager
def output_streams() -> Iterator[None]:
    """A command's run (``run_cli``): once ``check_writable`` accepts an output ``-``, standard output
    holds that output alone and whatever else the command prints goes to standard error, until the
    run ends."""
    claimed: list[TextIO] = []
    token = _CLAIMED.set(claimed)
    try:
        yield
    finally:
        _CLAIMED.reset(token)
        if claimed:
            sys.stdout.flush()
            sys.stdout = claimed[0]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path for ``path``'s content; on success move it into place (through a
    symbolic link: its target is replaced) or, for ``-``, copy it to standard output; on error
    delete it. The folder is not created.

    Raises:
        HlpError: ``path`` exists and is not a regular file (it is left untouched).
        StorageError: ``path``'s folder is missing or cannot be written, writing the temporary file
            failed (an ``OSError`` in the block, e.g. a full disk), or ``path`` cannot be replaced.
    """
    if is_stdout(path):
        with _stdout_path() as tmp:
            yield tmp
        return
    target = Path(os.path.realpath(path))
    kind = _kind(Path(path))
    if kind is not None:
        raise HlpError(f"{path}: cannot write: {kind}")
    if not target.parent.is_dir():
        raise StorageError(f"{path}: cannot write: the folder {target.parent} does not exist")
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as error:
        raise StorageError(f"{path}: cannot write: {_reason(error)}") from None
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
            raise StorageError(f"{path}: cannot write: {_reason(error, tmp)}") from None
    finally:
        tmp.unlink(missing_ok=True)


@contextlib.contextmanager
def _stdout_path() -> Iterator[Path]:
    """Yield a temporary file; on success copy it to standard output (the claimed one, see
    ``output_streams``), then delete it."""
    fd, tmp_name = tempfile.mkstemp(prefix=".stdout.", suffix=".tmp")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        claimed = _CLAIMED.get()
        stream = claimed[0] if claimed else sys.stdout
        try:
            stream.flush()
            data = tmp.read_bytes()
            if hasattr(stream, "buffer"):
                stream.buffer.write(data)
            else:
                stream.write(data.decode("utf-8", errors="replace"))
            stream.flush()
        except OSError as error:
            raise StorageError(f"standard output: cannot write: {_reason(error)}") from None
    finally:
        tmp.unlink(missing_ok=True)


def check_writable(*paths: str | os.PathLike[str] | None) -> None:
    """Refuse now the outputs a command could not write at its end (None: not asked for), so no work
    is lost to them and no output is written while another is refused: a path that exists and is
    not a regular file (followed through a symbolic link), a folder that does not exist or cannot be
    written (probed with a temporary file, removed at once; nothing is created), ``-`` twice. An
    accepted ``-`` claims standard output (see ``output_streams``).

    Raises:
        HlpError: one line per output that cannot be written.
    """
    given = [path for path in paths if path is not None]
    problems, refused = [], set()
    to_stdout = [path for path in given if is_stdout(path)]
    if len(to_stdout) > 1:
        problems.append(f"{STDOUT}: only one output can be standard output")
    for path in given:
        if is_stdout(path):
            continue
        kind = _kind(Path(path))
        if kind is not None:
            problems.append(f"{path}: cannot write: {kind}")
            continue
        folder = Path(os.path.realpath(path)).parent
        if folder in refused:  # one line for the outputs of a folder that cannot take any
            continue
        problem = _folder_problem(path, folder)
        if problem is not None:
            problems.append(problem)
            refused.add(folder)
    if problems:
        raise HlpError(*problems)
    if to_stdout:
        _claim_stdout()


def check_folder(path: str | os.PathLike[str], *names: str) -> Path:
    """Refuse now the output folder ``path`` that a command fills with the files ``names``: ``-``, a
    path that exists and is not a folder, a folder whose parent does not exist (the folder itself is
    made when written, its parent never), or files it could not write (``check_writable``).

    Returns:
        ``path`` as a ``Path``.

    Raises:
        HlpError: one line per problem.
    """
    if is_stdout(path):
        raise HlpError(f"{STDOUT}: an output folder cannot be standard output; name a folder")
    folder = Path(path)
    if Path(os.path.realpath(folder)).is_dir():
        check_writable(*(folder / name for name in names))
    elif folder.exists():
        raise HlpError(f"{folder}: cannot write: {_kind(folder) or 'it is a file'}, not a directory")
    else:
        check_writable(folder)  # not there yet: a name its existing parent can take
    return folder


def _kind(path: Path) -> str | None:
    """What ``path`` (a symbolic link followed) is when it exists and is not a regular file."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return None
    except OSError as error:  # e.g. a loop of symbolic links, or a parent that is a file
        if isinstance(error, NotADirectoryError):
            return None  # the folder's problem, said by _folder_problem
        return _reason(error)
    if stat.S_ISREG(mode):
        return None
    return f"it is {_KINDS.get(stat.S_IFMT(mode), 'not a regular file')}"


def _folder_problem(path: str | os.PathLike[str], folder: Path) -> str | None:
    """Why ``path`` cannot be written in ``folder`` (its real one), None if it can: probed with a
    temporary file, removed at once."""
    if not folder.exists():
        shown = Path(path).parent if Path(path).parent.resolve() == folder else folder
        return f"{path}: the folder {shown} does not exist"
    try:
        if not folder.is_dir():
            raise NotADirectoryError(0, "not a directory", str(folder))
        fd, probe = tempfile.mkstemp(prefix=f".{Path(path).name}.", suffix=".tmp", dir=folder)
    except OSError as error:
        return f"{path}: cannot write: {_reason(error)}"
    os.close(fd)
    os.unlink(probe)
    return None


def _claim_stdout() -> None:
    """Within ``output_streams``: keep standard output for the output ``-`` and send the rest of
    what the command prints to standard error."""
    claimed = _CLAIMED.get()
    if claimed is None or claimed:
        return
    sys.stdout.flush()
    claimed.append(sys.stdout)
    sys.stdout = sys.stderr


def _reason(error: OSError, written: Path | None = None) -> str:
    """``error`` in a few words, naming the path it is about (e.g. a parent that is a file) unless
    that is ``written``, the temporary file standing for the target."""
    if isinstance(error, FileExistsError | NotADirectoryError):
        return f"{error.filename} is not a directory"
    if error.filename and (written is None or Path(error.filename) != written):
        return f"{error.strerror or error} ({error.filename})"
    return str(error.strerror or error)


def write_text_atomic(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8); ``-``: to standard output."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
