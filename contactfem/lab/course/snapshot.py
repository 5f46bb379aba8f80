"""The submissions, copied before any of them runs.

:func:`take` copies every notebook of the submissions folder into the grader's private staging
folder: regular files only, read without following a link and without blocking (a FIFO is
refused, not opened for reading), each with the hash of its bytes and the time it was received
(its modification time when copied). What is graded, and when it counts as submitted, is this
copy, whatever happens to the folder afterwards.
"""

import hashlib
import os
import stat
from dataclasses import dataclass
from pathlib import Path

MAX_BYTES = 50 * 2**20  # a notebook with its outputs (figures) is a few MB; 50 MB is not a notebook


@dataclass(frozen=True)
class Received:
    """One submitted file: its path in the folder (posix), its private copy (None if refused, and
    `refused` says why), the SHA-256 of its bytes and its modification time (epoch seconds)."""

    rel: str
    copy: Path | None
    sha256: str = ""
    mtime: float = 0.0
    refused: str = ""


def notebooks(folder):
    """The paths of the *.ipynb entries of `folder` and its subfolders (links not followed;
    .ipynb_checkpoints left out), sorted; ValueError if it is no folder or holds none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"course grade: {folder} is not a folder of submitted notebooks")
    found = []
    for top, dirs, files in os.walk(folder, followlinks=False):
        dirs[:] = sorted(d for d in dirs if d != ".ipynb_checkpoints")
        found += [Path(top) / f for f in files if f.endswith(".ipynb")]
    if not found:
        raise ValueError(f"course grade: no notebooks (*.ipynb) in {folder}")
    return sorted(found)


def _copy(path, copy, max_bytes):
    """(sha256, mtime) of `path` copied to `copy`; ValueError saying why it is not copied."""
    st = os.lstat(path)
    if stat.S_ISLNK(st.st_mode):
        raise ValueError("a symbolic link, not a notebook")
    if not stat.S_ISREG(st.st_mode):
        raise ValueError("not a regular file (a FIFO, a device or a socket)")
    if st.st_size > max_bytes:
        raise ValueError(f"larger than {max_bytes / 2**20:g} MB")
    fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    try:
        st2 = os.fstat(fd)
        if not stat.S_ISREG(st2.st_mode) or (st2.st_dev, st2.st_ino) != (st.st_dev, st.st_ino):
            raise ValueError("replaced while it was being read")
        with os.fdopen(os.dup(fd), "rb") as f:
            data = f.read(max_bytes + 1)
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise ValueError(f"larger than {max_bytes / 2**20:g} MB")
    out = os.open(copy, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600)
    with os.fdopen(out, "wb") as f:
        f.write(data)
    return hashlib.sha256(data).hexdigest(), st2.st_mtime


def take(folder, staging, max_bytes=MAX_BYTES):
    """{path in the folder (posix): Received} for every notebook of `folder`, copied into the
    new folder `staging`."""
    folder, staging = Path(folder), Path(staging)
    staging.mkdir(mode=0o700)
    out = {}
    for i, path in enumerate(notebooks(folder)):
        rel = path.relative_to(folder).as_posix()
        copy = staging / f"{i:05d}.ipynb"
        try:
            digest, mtime = _copy(path, copy, max_bytes)
            out[rel] = Received(rel, copy, digest, mtime)
        except (ValueError, OSError) as err:
            why = str(err) if isinstance(err, ValueError) else f"cannot be read ({err.strerror})"
            out[rel] = Received(rel, None, refused=why)
    return out
