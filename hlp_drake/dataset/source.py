"""Where the VR dataset lives: its unpacked ``dataset/`` folder or ``.tar.xz`` archives.

The data may come in parts: the structured archive and archives laid over it (the unstructured
trials of ``hlp-vr-unstructured-part1.tar.xz``, which also replace some ``trial_results.csv``). A
``Source`` reads its parts in order; a file of a later part replaces the same file of an earlier one.
"""

from __future__ import annotations

import hashlib
import os
import re
import tarfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from hlp_drake.errors import DatasetError

ENV_VAR = "HLP_DATASET"
ARCHIVE_NAME = "hlp-vr-dataset.tar.xz"
OVERLAY_PATTERN = "hlp-vr-*-part*.tar.xz"  # archives laid over the structured one, in name order
PARTICIPANTS_FILE = "participant_list.csv"
_SUBJECT_DIR = re.compile(r"^sub_\d+$")
WHERE_TO_GET = "the dataset/ folder of github.com/m-hasan-n/human-like-planning, or hlp-vr-dataset.tar.xz"


def dataset_relative_path(name: str) -> str | None:
    """Path of a file relative to the dataset root (``sub_01/T050/...``), or None if outside it.

    Hidden files (e.g. LibreOffice lock files) are outside.
    """
    parts = [p for p in name.replace("\\", "/").split("/") if p not in ("", ".")]
    if not parts or any(p.startswith(".") for p in parts):
        return None
    for i, part in enumerate(parts):
        if _SUBJECT_DIR.match(part) and i < len(parts) - 1:
            return "/".join(parts[i:])
    if parts[-1] == PARTICIPANTS_FILE:
        return PARTICIPANTS_FILE
    return None


MAX_FILE_BYTES = 16 << 20
"""A dataset file larger than this is reported and left out unread (the largest is about 0.3 MB)."""


def _too_large() -> OSError:
    return OSError(f"larger than {MAX_FILE_BYTES >> 20} MiB, not a file of the dataset")


@dataclass(frozen=True)
class SourcePart:
    """One readable copy of (part of) the dataset.

    Attributes:
        path: the folder holding ``sub_XX/`` (and ``participant_list.csv``), or the archive file.
        is_archive: True for a tar archive (read by streaming through it once).
    """

    path: Path
    is_archive: bool

    def fingerprint(self, digest) -> None:
        """Feed ``digest`` with what changes whenever a file of the part changes (path, size, mtime)."""
        digest.update(str(self.path).encode())
        if self.is_archive:
            stat = self.path.stat()
            digest.update(f"{stat.st_size}:{stat.st_mtime_ns}".encode())
            return
        for relative, full in sorted(self._walk()):
            stat = os.stat(full)
            digest.update(f"{relative}:{stat.st_size}:{stat.st_mtime_ns}\n".encode())

    def _walk(self) -> Iterator[tuple[str, str]]:
        for root, dirs, files in os.walk(self.path):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in files:
                full = os.path.join(root, name)
                relative = dataset_relative_path(os.path.relpath(full, self.path))
                if relative is not None:
                    yield relative, full

    def size(self) -> int:
        """Bytes to read (the archive's size, or the sum of the files')."""
        if self.is_archive:
            return self.path.stat().st_size
        return sum(os.path.getsize(full) for _, full in self._walk())

    def files(self, progress: tqdm | None = None) -> Iterator[tuple[str, bytes | OSError]]:
        """Yield (path relative to the dataset root, content or the error met reading it)."""
        if self.is_archive:
            yield from self._archive_files(progress)
            return
        for relative, full in list(self._walk()):
            try:
                size = os.path.getsize(full)
                if size > MAX_FILE_BYTES:
                    if progress is not None:
                        progress.update(size)
                    yield relative, _too_large()
                    continue
                content = Path(full).read_bytes()
            except OSError as error:
                yield relative, error
                continue
            if progress is not None:
                progress.update(len(content))
            yield relative, content

    def _archive_files(self, progress: tqdm | None) -> Iterator[tuple[str, bytes | OSError]]:
        try:
            with open(self.path, "rb") as raw, tarfile.open(fileobj=raw, mode="r|*") as archive:
                done = progress.n if progress is not None else 0
                for member in archive:
                    if progress is not None:
                        progress.update(done + raw.tell() - progress.n)
                    relative = dataset_relative_path(member.name)
                    if relative is None or not member.isfile():
                        continue
                    if member.size > MAX_FILE_BYTES:
                        yield relative, _too_large()
                        continue
                    handle = archive.extractfile(member)
                    yield relative, handle.read() if handle else OSError("not a regular file")
        except (tarfile.TarError, EOFError, OSError) as error:
            raise DatasetError(f"{self.path}: cannot read the archive: {error}") from None

    def describe(self, relative: str) -> str:
        """A path a user can find: inside the archive or on disk."""
        return f"{self.path}:{relative}" if self.is_archive else str(self.path / relative)


@dataclass(frozen=True)
class Source:
    """The dataset's parts, read in order (a later part's file replaces an earlier one's).

    Attributes:
        parts: the structured data first, then the parts laid over it.
    """

    parts: tuple[SourcePart, ...]

    @property
    def path(self) -> Path:
        """The first part's path."""
        return self.parts[0].path

    def describe_parts(self) -> str:
        """The parts' paths, joined with " + "."""
        return " + ".join(str(p.path) for p in self.parts)

    def fingerprint(self) -> str:
        """Changes whenever a file of any part changes (path, size and modification time)."""
        digest = hashlib.sha256()
        for part in self.parts:
            part.fingerprint(digest)
        return digest.hexdigest()

    def files(self, progress: tqdm | None = None) -> Iterator[tuple[str, str, bytes | OSError]]:
        """Yield (path relative to the dataset root, where a user finds it, content or the error
        met reading it) for every part in order.

        Args:
            progress: a byte-counting progress bar to advance (its total is set here).
        """
        if progress is not None:
            progress.total = sum(part.size() for part in self.parts)
        for part in self.parts:
            for relative, content in part.files(progress):
                yield relative, part.describe(relative), content


def _looks_like_root(folder: Path) -> bool:
    if (folder / PARTICIPANTS_FILE).is_file():
        return True
    return any(child.is_dir() and _SUBJECT_DIR.match(child.name) for child in folder.iterdir())


def _resolve_part(given: Path) -> list[SourcePart]:
    if not given.exists():
        raise DatasetError(f"{given}: no such file or directory ({WHERE_TO_GET})")
    resolved = given.resolve()
    if resolved.is_file():
        if not tarfile.is_tarfile(resolved):
            raise DatasetError(f"{given}: not a tar archive of the VR dataset")
        return [SourcePart(resolved, is_archive=True)]
    for candidate in (resolved, resolved / "dataset", resolved / "hlp-vr-dataset" / "dataset"):
        if candidate.is_dir() and _looks_like_root(candidate):
            return [SourcePart(candidate, is_archive=False)]
    if (resolved / ARCHIVE_NAME).is_file():
        overlays = sorted(resolved.glob(OVERLAY_PATTERN))
        return [part for path in (resolved / ARCHIVE_NAME, *overlays) for part in _resolve_part(path)]
    raise DatasetError(
        f"{given}: no VR dataset here (expected sub_XX folders, a dataset/ folder or {ARCHIVE_NAME})"
    )


def default_dataset(project: Path | None = None) -> Path | None:
    """Where the dataset is read from when neither a path nor ``HLP_DATASET`` is given: ``shared/data``
    beside the project folder (``../shared/data`` from it) when the package runs from a source checkout
    (the folder holding ``hlp_drake/`` holds ``pyproject.toml``: ``pip install -e .``) and that folder
    exists; else None (an installed package has no project folder to look beside).

    Args:
        project: the project folder (default: the one holding this package).
    """
    project = Path(__file__).resolve().parents[2] if project is None else project
    if not (project / "pyproject.toml").is_file():
        return None
    data = project.parent / "shared" / "data"
    return data if data.is_dir() else None


def resolve_source(path: str | os.PathLike[str] | Sequence[str | os.PathLike[str]] | None = None) -> Source:
    """Find the dataset from ``path`` or, when it is None, from the ``HLP_DATASET`` variable, else
    ``default_dataset()`` (``../shared/data`` beside a source checkout).

    Accepted: an archive, the unpacked ``dataset/`` folder, a folder holding ``dataset/``,
    ``hlp-vr-dataset/dataset/`` or the archive (e.g. ``../shared/data``; the archives named
    ``OVERLAY_PATTERN`` beside it are laid over it), or several of these in order (a sequence, or
    ``HLP_DATASET`` with paths joined by ``os.pathsep``), each laid over the ones before.

    Raises:
        DatasetError: nothing given, a path does not exist, or holds no dataset.
    """
    if path is None:
        text = os.environ.get(ENV_VAR) or None
        default = default_dataset() if text is None else None
        if text is None and default is None:
            raise DatasetError(
                f"no dataset given: pass --dataset PATH, set {ENV_VAR} or, in a source checkout, place it "
                f"in ../shared/data beside the project folder ({WHERE_TO_GET})"
            )
        paths = [default] if text is None else [p for p in text.split(os.pathsep) if p]
    elif isinstance(path, (str, os.PathLike)):
        paths = [path]
    else:
        paths = list(path)
    if not paths:
        raise DatasetError(f"no dataset given ({WHERE_TO_GET})")
    return Source(tuple(part for p in paths for part in _resolve_part(Path(p).expanduser())))
