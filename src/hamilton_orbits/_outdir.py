"""The output folder of a command, claimed before anything runs.

A run that ends by writing into a folder should learn *before* it runs that it
cannot: ``--out`` naming a file, or a folder that cannot be created or written,
would lose the whole run at save time.  And two runs writing into one folder at
once would mix their files.  :class:`OutputFolder` checks the folder, creates it
and takes a lock file in it (``.hamilton-orbits.lock``, holding the PID and the
host of the run), refused while the run that holds it is alive; a lock left by
a run that has ended (its process is gone) is taken over.  The lock goes when
the run ends.
"""

from __future__ import annotations

import itertools
import os
import re
import socket
import time
from pathlib import Path

from hamilton_orbits.integrators._held import held

try:
    import fcntl
except ImportError:  # pragma: no cover - platforms without flock: takeovers unguarded
    fcntl = None  # type: ignore[assignment]

__all__ = ["LOCK_NAME", "FolderError", "OutputFolder", "live_holder"]

LOCK_NAME = ".hamilton-orbits.lock"
_CLAIMS = itertools.count(1)


class FolderError(ValueError):
    """An output folder that cannot be used (its message says why, naming it)."""


#: the claims of this process that hold their folder's lock (a lock of this
#: process's PID and host with another number is a former process's: a container
#: restarted with the same PID)
_HELD: set[int] = set()


def _alive(pid: int) -> bool:
    """True if a process ``pid`` runs on this host (an ended one whose parent has
    not yet collected it, a zombie, has ended)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by someone else
        pass
    except OSError:  # pragma: no cover - platforms without signal 0
        return True
    try:  # (Linux: its state, after the command's name in parentheses)
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True


def live_holder(folder: str | Path) -> int | None:
    """The PID of the run of this machine that holds ``folder``'s lock and is alive
    (this process's own included); None for no lock, a run that has ended, or one of
    another machine (whose life cannot be told from here).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     with OutputFolder(tmp):
    ...         live_holder(tmp) == os.getpid()
    ...     live_holder(tmp)
    True
    """
    try:
        held = (Path(folder) / LOCK_NAME).read_text(encoding="utf-8", errors="replace").split()
    except OSError:
        return None
    if len(held) < 2 or not re.fullmatch(r"[0-9]{1,9}", held[0]) or \
            held[1] != socket.gethostname():
        return None
    pid = int(held[0])
    if pid == os.getpid():  # (a former process of this PID's lock, a container restarted,
        claim = held[2] if len(held) > 2 else ""  # is stale: as _judge has it)
        return pid if re.fullmatch(r"[0-9]{1,9}", claim) and int(claim) in _HELD else None
    return pid if _alive(pid) else None


def _hold(fd: int, patience: float = 2.0) -> None:
    """Hold an exclusive ``flock`` on file ``fd`` (released when it is closed, or
    its process ends); another run taking the same lock over holds it for
    microseconds: waited for, up to ``patience`` seconds."""
    if fcntl is None:  # pragma: no cover - platforms without flock
        return
    give_up = time.monotonic() + patience
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() > give_up:
                raise
            time.sleep(0.001)


class OutputFolder:
    """Claim folder ``path`` for one run: ``with OutputFolder(path, "--out"): ...``.

    Parameters
    ----------
    path : str or Path
        The folder (created with its parents if missing).
    option : str
        How the user named it, for messages (``"--out"``).

    Raises
    ------
    FolderError
        On entering: ``path`` is a file, cannot be created or written, or another
        live run holds it (naming its PID and host).

    Examples
    --------
    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     with OutputFolder(tmp) as folder:
    ...         (folder.path / LOCK_NAME).exists()
    ...     (folder.path / LOCK_NAME).exists()
    True
    False
    """

    def __init__(self, path: str | Path, option: str = "--out") -> None:
        self.path = Path(path)
        self.option = option
        self._lock = self.path / LOCK_NAME
        #: the lock's text: the PID and host, and a number of this claim's own (two
        #: claims of one process told apart: a claim releases only its own lock)
        self._claim = next(_CLAIMS)
        self._mine = f"{os.getpid()} {socket.gethostname()} {self._claim}\n"
        #: whether entering made the folder (it then holds nothing but the lock)
        self.made = False

    def _fail(self, why: str) -> FolderError:
        return FolderError(f"{self.option} {self.path}: {why}; nothing was run")

    def __enter__(self) -> OutputFolder:
        self._make()
        _HELD.add(self._claim)  # (before its lock is linked, until it is released)
        try:
            return self._claim_lock()
        except BaseException:
            _HELD.discard(self._claim)
            raise

    @held
    def _claim_lock(self) -> OutputFolder:
        """Take the folder's lock (:meth:`__enter__`)."""
        # the lock is written whole under a name of its own, then linked to its name
        # (atomic, and refused if the name exists): a run killed at any moment leaves
        # no empty lock that would look like an unknown run's
        mine = os.path.join(self.path, f"{LOCK_NAME}.{os.getpid()}.{self._claim}")
        try:
            fd = os.open(mine, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o666)
            try:
                os.write(fd, self._mine.encode("utf-8"))
            finally:
                os.close(fd)
            for _attempt in range(2):
                try:
                    os.link(mine, self._lock)
                except FileExistsError:
                    self._take_over_stale()
                    continue
                return self
        except OSError as exc:
            raise self._fail(f"cannot write in the folder ({exc.strerror or exc})") from None
        finally:
            try:
                os.unlink(mine)
            except OSError:
                pass
        raise self._fail("another run keeps taking the folder")  # pragma: no cover

    def _make(self) -> None:
        """The folder, made with its parents where missing; a file of its name, or a
        folder that cannot be made, refused."""
        try:  # (one mkdir where the parents are there; they are made first where not)
            self.path.mkdir(parents=True)
            self.made = True
        except FileExistsError:  # (there already, or made meanwhile by another run)
            if not os.path.isdir(self.path):
                raise self._fail("is a file, not a folder") from None
        except OSError as exc:
            raise self._fail(f"cannot create the folder ({exc.strerror or exc})") from None

    @held
    def _take_over_stale(self) -> None:
        """Remove the lock of a run that has ended; refuse one of a live run.

        The lock is held (``flock``) while it is judged and removed, and removed
        only while it is still the folder's lock: of two runs that find one stale
        lock at once, one takes it over and the other, after it, finds the
        winner's lock (otherwise the second would remove the first's new lock as
        "the stale one", and both would write)."""
        try:
            fd = os.open(self._lock, os.O_RDONLY)
        except FileNotFoundError:  # released meanwhile
            return
        try:
            try:
                _hold(fd)
            except BlockingIOError:
                raise self._fail("another run keeps taking the folder over") from None
            try:
                if not os.path.samestat(os.fstat(fd), os.stat(self._lock)):
                    return  # (taken over or released meanwhile: tried again)
            except FileNotFoundError:
                return
            self._judge(os.read(fd, 4096).decode("utf-8", errors="replace").split())
        finally:
            os.close(fd)

    def _judge(self, held: list[str]) -> None:
        """Remove the lock whose text is ``held`` (PID, host, claim) if its run has
        ended; refuse it otherwise (a text that is no lock's: an unknown run's)."""
        pid = int(held[0]) if held and re.fullmatch(r"[0-9]{1,9}", held[0]) else None
        host = held[1] if len(held) > 1 else "?"
        claim = int(held[2]) if len(held) > 2 and re.fullmatch(r"[0-9]{1,9}", held[2]) else None
        here = pid is not None and host == socket.gethostname()
        if here and (not _alive(pid) if pid != os.getpid() else claim not in _HELD):
            self._lock.unlink(missing_ok=True)  # (ended, or a former process's of this PID)
            return
        if here and pid == os.getpid():
            raise self._fail(f"another run of this same process (PID {pid}: a simulation "
                             f"writing its archive) is writing into this folder; choose "
                             f"another folder")
        who = f"PID {pid} on {host}" if pid is not None else "an unknown run"
        raise self._fail(
            f"another run ({who}) is writing into this folder; choose another folder, or "
            f"wait for it to end (if it has ended on another machine, delete {self._lock})")

    @held
    def __exit__(self, *exc_info: object) -> None:
        try:
            fd = os.open(self._lock, os.O_RDONLY)
            try:
                held = os.read(fd, 4096)
            finally:
                os.close(fd)
            if held == self._mine.encode("utf-8"):
                os.unlink(self._lock)
        except OSError:  # gone already (a user removed it): nothing to release
            pass
        finally:
            _HELD.discard(self._claim)
