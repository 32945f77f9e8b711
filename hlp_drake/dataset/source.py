"""Where the VR dataset lives: its unpacked ``dataset/`` folder or the ``.tar.xz`` archive."""

from __future__ import annotations

import hashlib
import os
import re
import tarfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from hlp_drake.errors import DatasetError

ENV_VAR = "HLP_DATASET"
ARCHIVE_NAME = "hlp-vr-dataset.tar.xz"
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


@dataclass(frozen=True)
class Source:
    """A readable copy of the dataset.

    Attributes:
        path: the folder holding ``sub_XX/`` (and ``participant_list.csv``), or the archive file.
        is_archive: True for a tar archive (read by streaming through it once).
    """

    path: Path
    is_archive: bool

    def fingerprint(self) -> str:
        """Changes whenever a file of the dataset changes (path, size and modification time)."""
        digest = hashlib.sha256(str(self.path).encode())
        if self.is_archive:
            stat = self.path.stat()
            digest.update(f"{stat.st_size}:{stat.st_mtime_ns}".encode())
        else:
            for relative, full in sorted(self._walk()):
                stat = os.stat(full)
                digest.update(f"{relative}:{stat.st_size}:{stat.st_mtime_ns}\n".encode())
        return digest.hexdigest()

    def _walk(self) -> Iterator[tuple[str, str]]:
        for root, dirs, files in os.walk(self.path):
            dirs[:] = sorted(d for d in dirs if not d.startswith("."))
            for name in files:
                full = os.path.join(root, name)
                relative = dataset_relative_path(os.path.relpath(full, self.path))
                if relative is not None:
                    yield relative, full

    def files(self, progress: tqdm | None = None) -> Iterator[tuple[str, bytes | OSError]]:
        """Yield (path relative to the dataset root, content or the error met reading it).

        Args:
            progress: a byte-counting progress bar to advance (its total is set here).
        """
        if self.is_archive:
            yield from self._archive_files(progress)
            return
        entries = list(self._walk())
        if progress is not None:
            progress.total = sum(os.path.getsize(full) for _, full in entries)
        for relative, full in entries:
            try:
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
                if progress is not None:
                    progress.total = self.path.stat().st_size
                for member in archive:
                    if progress is not None:
                        progress.update(raw.tell() - progress.n)
                    relative = dataset_relative_path(member.name)
                    if relative is None or not member.isfile():
                        continue
                    handle = archive.extractfile(member)
                    yield relative, handle.read() if handle else OSError("not a regular file")
        except (tarfile.TarError, EOFError, OSError) as error:
            raise DatasetError(f"{self.path}: cannot read the archive: {error}") from None

    def describe(self, relative: str) -> str:
        """A path a user can find: inside the archive or on disk."""
        return f"{self.path}:{relative}" if self.is_archive else str(self.path / relative)


def _looks_like_root(folder: Path) -> bool:
    if (folder / PARTICIPANTS_FILE).is_file():
        return True
    return any(child.is_dir() and _SUBJECT_DIR.match(child.name) for child in folder.iterdir())


def resolve_source(path: str | os.PathLike[str] | None = None) -> Source:
    """Find the dataset from ``path`` or, when it is None, from the ``HLP_DATASET`` variable.

    Accepted: the archive, the unpacked ``dataset/`` folder, a folder holding ``dataset/``,
    ``hlp-vr-dataset/dataset/`` or the archive (e.g. ``../shared/data``).

    Raises:
        DatasetError: nothing given, the path does not exist, or holds no dataset.
    """
    if path is None:
        path = os.environ.get(ENV_VAR) or None
        if path is None:
            raise DatasetError(f"no dataset given: pass --dataset PATH or set {ENV_VAR} ({WHERE_TO_GET})")
    given = Path(path).expanduser()
    if not given.exists():
        raise DatasetError(f"{given}: no such file or directory ({WHERE_TO_GET})")
    resolved = given.resolve()
    if resolved.is_file():
        if not tarfile.is_tarfile(resolved):
            raise DatasetError(f"{given}: not a tar archive of the VR dataset")
        return Source(resolved, is_archive=True)
    for candidate in (resolved, resolved / "dataset", resolved / "hlp-vr-dataset" / "dataset"):
        if candidate.is_dir() and _looks_like_root(candidate):
            return Source(candidate, is_archive=False)
    if (resolved / ARCHIVE_NAME).is_file():
        return resolve_source(resolved / ARCHIVE_NAME)
    raise DatasetError(f"{given}: no VR dataset here (expected sub_XX folders, a dataset/ folder or {ARCHIVE_NAME})")
