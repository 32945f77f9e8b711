"""Output paths (``hlp_drake.files.atomic``): what is refused before any work and left untouched (a
device, a named pipe, a folder, a missing folder), a symbolic link written through, ``-`` as standard
output, an output folder made but never its parent."""

from __future__ import annotations

import os
import stat
import sys

import pytest

from hlp_drake.errors import HlpError
from hlp_drake.files.atomic import check_folder, check_writable, output_streams, write_text_atomic


def _is_char_device(path: os.PathLike[str]) -> bool:
    return stat.S_ISCHR(os.stat(path).st_mode)


@pytest.fixture
def fifo(tmp_path):
    """A named pipe nobody reads: opening it for writing would block, so a test passing never opened it."""
    path = tmp_path / "fifo"
    os.mkfifo(path)
    return path


def test_a_character_device_is_refused_and_left_a_device(char_device):
    with pytest.raises(HlpError) as info:
        check_writable(char_device)
    assert info.value.problems == (f"{char_device}: cannot write: it is a character device",)
    with pytest.raises(HlpError, match="character device"), output_streams():
        write_text_atomic(char_device, "{}")  # refused at the write too, not replaced
    assert _is_char_device(char_device)


def test_a_named_pipe_is_refused_without_being_opened(tmp_path, fifo):
    with pytest.raises(HlpError) as info:
        check_writable(fifo)
    assert info.value.problems == (f"{fifo}: cannot write: it is a named pipe",)
    with pytest.raises(HlpError, match="named pipe"):
        write_text_atomic(fifo, "{}")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and sorted(tmp_path.iterdir()) == [fifo]


def test_a_symbolic_link_is_written_through_and_kept(tmp_path, fifo):
    target, link = tmp_path / "target.json", tmp_path / "link.json"
    link.symlink_to(target)  # dangling: the target is made in its existing folder
    check_writable(link)
    write_text_atomic(link, "1\n")
    assert link.is_symlink() and target.read_text() == "1\n"
    write_text_atomic(link, "2\n")  # an existing target replaced, the link kept
    assert link.is_symlink() and os.readlink(link) == str(target) and target.read_text() == "2\n"
    (to_pipe := tmp_path / "to_pipe").symlink_to(fifo)
    (to_nowhere := tmp_path / "to_nowhere").symlink_to(tmp_path / "missing" / "r.json")
    with pytest.raises(HlpError) as info:
        check_writable(to_pipe, to_nowhere)
    assert info.value.problems == (
        f"{to_pipe}: cannot write: it is a named pipe",
        f"{to_nowhere}: the folder {tmp_path / 'missing'} does not exist",
    )
    assert to_pipe.is_symlink() and stat.S_ISFIFO(os.stat(to_pipe).st_mode)


def test_a_missing_folder_is_refused_by_name_and_never_made(tmp_path):
    missing = tmp_path / "nonexistent" / "dir"
    with pytest.raises(HlpError) as info:
        check_writable(missing / "r.json")
    assert info.value.problems == (f"{missing / 'r.json'}: the folder {missing} does not exist",)
    with pytest.raises(HlpError, match="does not exist"):
        write_text_atomic(missing / "r.json", "{}")
    assert list(tmp_path.iterdir()) == []


def test_dash_is_standard_output_and_the_rest_of_the_prints_go_to_stderr(capsys):
    with output_streams():
        print("before")
        check_writable("-", None)
        print("wrote -")  # a command's status line, after the outputs were accepted
        write_text_atomic("-", '{"a": 1}\n')
    print("after")  # the run over: standard output is back
    out, err = capsys.readouterr()
    assert out == 'before\n{"a": 1}\nafter\n' and err == "wrote -\n"
    with pytest.raises(HlpError, match="only one output can be standard output"), output_streams():
        check_writable("-", "-")
    assert sys.stdout is not sys.stderr


def test_an_output_folder_is_made_but_never_its_parent(tmp_path, fifo, char_device):
    (a_file := tmp_path / "a_file").write_text("x")
    assert check_folder(tmp_path / "new", "r.json") == tmp_path / "new"  # made when written
    refused = {
        "-": "-: an output folder cannot be standard output; name a folder",
        str(a_file): f"{a_file}: cannot write: it is a file, not a directory",
        str(fifo): f"{fifo}: cannot write: it is a named pipe, not a directory",
        str(char_device): f"{char_device}: cannot write: it is a character device, not a directory",
        str(
            tmp_path / "no" / "out"
        ): f"{tmp_path / 'no' / 'out'}: the folder {tmp_path / 'no'} does not exist",
    }
    for path, message in refused.items():
        with pytest.raises(HlpError) as info:
            check_folder(path, "r.json")
        assert info.value.problems == (message,)
    (linked := tmp_path / "linked").symlink_to(tmp_path)  # a link to a folder: written through
    (tmp_path / "r.json").mkdir()
    with pytest.raises(HlpError, match="r.json: cannot write: it is a directory"):
        check_folder(linked, "r.json")
    assert {"a_file", "fifo", "linked", "r.json"} <= {p.name for p in tmp_path.iterdir()}
    assert not (tmp_path / "new").exists() and _is_char_device(char_device)
