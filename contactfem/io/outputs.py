"""Output files written all or nothing.

    out = Outputs()
    out.add("--json", "run.json", (".json",))     # checked now: before any run
    ...                                            # the run
    with out:                                      # on any exception: the temporaries are removed
        write_json(out.temp("--json"))             # each file goes to a temporary beside its target
        out.commit()                               # then all are renamed into place together

Missing folders of an output path are made when it is written (and removed again if the
run writes nothing); the nearest existing one must be a folder where files can be created.
A file is never seen half written: each is written under a temporary name in the target's
folder (``.<name>.<random>.part<suffix>``) and renamed (``os.replace``, atomic on one file
system) only when every output is complete. During the renames Ctrl-C is held back, so an
interrupted run leaves either none or all of its outputs.
"""

import os
import secrets
import signal
import threading
from pathlib import Path


# One rule for every command's outputs (files and folders alike): the folders of an output path
# that do not exist yet are made, as a file manager's "save as" makes a new folder; what must
# already exist is their nearest existing parent, a folder where files can be created. The
# check comes before any work; the folders are made when the output is written.


def check_output_path(path, what, suffixes):
    """ValueError (one line naming the option) unless `path` can be written: not empty, an
    allowed suffix, not a folder, and in a folder that exists or can be made (its nearest
    existing parent a folder where files can be created). Makes nothing (``make_parents``
    does, when the file is written)."""
    if not str(path).strip():
        raise ValueError(
            f"{what}: empty file name; give a file name{' ending in ' + ' or '.join(suffixes) if suffixes else ''}"
        )
    p = Path(path)
    if suffixes and p.suffix.lower() not in suffixes:
        raise ValueError(f"{what} {path}: the file name must end in {' or '.join(suffixes)}")
    if p.is_dir():
        raise ValueError(f"{what} {path}: is a folder, give a file name")
    folder = p.parent if str(p.parent) else Path(".")
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{what} {path}: {folder} is a file, not a folder")
    _writable_ancestor(folder, what, path)
    return p


def check_output_dir(path, what):
    """ValueError (one line naming the option) unless `path` is a folder that exists or can
    be made: not empty, not a file, and its nearest existing parent a folder where files can
    be created. Makes nothing."""
    if not str(path).strip():
        raise ValueError(f"{what}: empty folder name; give a folder")
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise ValueError(f"{what} {path}: is a file, give a folder")
    _writable_ancestor(p, what, path)
    return p


def _writable_ancestor(p, what, path):
    """The nearest existing folder of ``p`` (``p`` itself if it exists), checked writable."""
    parent = p
    while not parent.exists():
        if parent.parent == parent:
            break
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"{what} {path}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{what} {path}: cannot write in {parent} (permission denied)")
    _probe(parent, what, path)  # (a special file system may refuse what access allows)
    return parent


def make_parents(path):
    """Make the missing folders above the output file ``path``; returns those made (outermost
    first), for a writer that removes them again if it writes nothing."""
    made, folder = [], Path(path).parent
    while str(folder) and not folder.exists():
        made.append(folder)
        folder = folder.parent
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    return made[::-1]


def _probe(folder, what, path):
    """ValueError naming the option unless a file can be created (and removed) in `folder`."""
    probe = Path(folder) / f".contactfem.{secrets.token_hex(4)}.probe"
    try:
        try:
            open(probe, "xb").close()
        finally:
            probe.unlink(missing_ok=True)  # also when a Ctrl-C comes between the two
    except OSError as err:
        raise ValueError(f"{what} {path}: cannot write in {folder} ({err.strerror or err})") from None


class Outputs:
    """The output files of one run: validated when added, written to temporaries, renamed
    into place together by commit(). As a context manager it removes the temporaries if
    the block ends with an exception (Ctrl-C included)."""

    def __init__(self):
        self.paths = {}  # option -> target Path
        self.temps = {}  # option -> temporary Path
        self.made = []  # folders made for the outputs (removed again if nothing is written)
        self.committed = False

    def add(self, what, path, suffixes=()):
        p = check_output_path(path, what, suffixes)
        for other, q in self.paths.items():
            if q.resolve() == p.resolve():
                raise ValueError(f"{what} {path}: the same file as {other}")
        self.paths[what] = p
        return p

    def temp(self, what):
        """The temporary file name to write the output `what` to (same folder, same suffix)."""
        p = self.paths[what]
        self.made += make_parents(p)
        t = p.with_name(f".{p.stem}.{secrets.token_hex(4)}.part{p.suffix}")
        self.temps[what] = t
        return t

    def commit(self):
        """Rename every temporary onto its target, with Ctrl-C held back until all are done.
        If a rename fails, the outputs already moved are removed again (none or all). Returns
        (option, path, replaced) for each output written: replaced, where a file was there before
        (the command says so: a user's file is never replaced silently)."""
        done, written = [], []
        with hold_interrupts():
            try:
                for what, t in self.temps.items():
                    replaced = self.paths[what].exists()
                    os.replace(t, self.paths[what])
                    done.append(self.paths[what])
                    written.append((what, str(self.paths[what]), replaced))
            except OSError:
                for p in done:
                    p.unlink(missing_ok=True)
                raise
            self.committed = True
        return written

    def discard(self):
        for t in self.temps.values():
            try:
                t.unlink(missing_ok=True)
            except OSError:
                pass
        for folder in reversed(self.made):  # innermost first; only if still empty
            try:
                folder.rmdir()
            except OSError:
                pass

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if not self.committed:
            self.discard()
        return False


class hold_interrupts:
    """Hold SIGINT back for the duration of the block; a Ctrl-C that arrived meanwhile
    is raised as KeyboardInterrupt at the end. (No-op outside the main thread.)"""

    def __enter__(self):
        self.pending = False
        self.active = threading.current_thread() is threading.main_thread()
        if self.active:
            self.previous = signal.signal(signal.SIGINT, self._hold)
        return self

    def _hold(self, signum, frame):
        self.pending = True

    def __exit__(self, kind, exc, tb):
        if self.active:
            signal.signal(signal.SIGINT, self.previous)
            if self.pending and kind is None:
                raise KeyboardInterrupt
        return False


def write_atomic(path, data):
    """Write `data` (bytes or text) to `path` through a temporary file of its folder, created
    afresh (never through a symbolic link), then renamed onto `path`: a reader sees the old file
    or the new one, and a symbolic link at `path` is replaced, not followed."""
    path = Path(path)
    data = data.encode() if isinstance(data, str) else data
    tmp = path.with_name(f".{path.name}.{secrets.token_hex(4)}.part")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def own_dir(path, what):
    """The folder `path`, made (with its parents) if missing; ValueError naming the option if it
    is a symbolic link or not a folder (what is written there must land there, not where a link
    points)."""
    path = Path(path)
    if path.is_symlink():
        raise ValueError(f"{what} {path}: a symbolic link; give a real folder")
    if path.exists() and not path.is_dir():
        raise ValueError(f"{what} {path}: a file, not a folder")
    path.mkdir(parents=True, exist_ok=True)
    return path
