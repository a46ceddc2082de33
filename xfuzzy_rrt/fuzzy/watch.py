"""Change notices for rulebook directories: Linux inotify, so a cached rulebook is re-validated
by one poll instead of one ``stat`` per file.

Why: every plan call without a loaded rulebook looks its directory up
(:func:`~xfuzzy_rrt.fuzzy.rulebook.load_rulebook_cached`). Checking the stamps of the directory,
its manifest and six FIS files is eight ``stat`` calls, ~3 us each in a VM: a quarter of a
0.1 ms call budget. A :class:`Watch` asks the kernel to report any change instead; while
nothing was reported, the look-up is one ``poll`` (~0.7 us) plus one ``stat`` of the directory
path (which catches what no watch on the directory can: a parent renamed, a symlink on the
path pointed elsewhere).

What a watch sees: it is armed *before* the caller reads the files, on the directory (a file
added, removed, renamed, written or re-stamped) and on each content file's inode (so a write
through a hard link elsewhere counts too). Any event on any of them, including a queue
overflow, makes the watch stale for good; the caller then re-reads and arms a new one. Reading
the files (our own hashing) generates no event it listens to.

Where it is not used (:func:`arm` returns ``None`` and the caller keeps checking stamps):
not Linux, no inotify (or its instance or watch limit reached), or a file on a file system
whose changes may come from elsewhere without a local event: NFS, SMB, 9p, FUSE (virtiofs,
Docker Desktop's shares) and anything not on :data:`LOCAL_FILE_SYSTEMS`. Writes through a
shared memory mapping produce no event either; nothing in the project edits a rulebook that
way, and the stamp check would not see them before write-back anyway.

Processes: a forked child never reads its parent's notices (they would be taken from the
parent's queue); after a fork every inherited watch is stale and the child opens its own.
Threads: a thread that finds events pending, or another thread reading them, waits for the
reader to mark what they touched before it trusts its watch.
"""

from __future__ import annotations

import ctypes
import os
import select
import struct
import sys
import threading
import weakref

# <sys/inotify.h>
IN_MODIFY = 0x002
IN_ATTRIB = 0x004
IN_CLOSE_WRITE = 0x008
IN_MOVED_FROM = 0x040
IN_MOVED_TO = 0x080
IN_CREATE = 0x100
IN_DELETE = 0x200
IN_DELETE_SELF = 0x400
IN_MOVE_SELF = 0x800
IN_NONBLOCK = os.O_NONBLOCK
IN_CLOEXEC = os.O_CLOEXEC
#: What a directory watch listens to: its entries changing, a child written or re-stamped,
#: the directory itself moved or removed.
DIR_EVENTS = (IN_MODIFY | IN_ATTRIB | IN_CLOSE_WRITE | IN_MOVED_FROM | IN_MOVED_TO | IN_CREATE
              | IN_DELETE | IN_DELETE_SELF | IN_MOVE_SELF)
#: What a file watch listens to (the inode, whatever name it is written through).
FILE_EVENTS = IN_MODIFY | IN_ATTRIB | IN_CLOSE_WRITE | IN_DELETE_SELF | IN_MOVE_SELF

#: ``statfs`` magic numbers of local file systems, whose every change goes through this kernel
#: (``<linux/magic.h>``): ext2/3/4, XFS, Btrfs, tmpfs, ramfs, overlayfs (containers), F2FS,
#: ZFS, bcachefs, JFS, ReiserFS, NILFS, SquashFS (read-only).
LOCAL_FILE_SYSTEMS = frozenset({
    0xEF53, 0x58465342, 0x9123683E, 0x01021994, 0x858458F6, 0x794C7630, 0xF2F52010,
    0x2FC12FC1, 0xCA451A4E, 0x3153464A, 0x52654973, 0x3434, 0x73717368,
})

_EVENT = struct.Struct("iIII")  # wd, mask, cookie, len (then len bytes of name)

#: Set to False to never watch (the stamp check alone decides); tests compare both.
ENABLED = True


class _Notifier:
    """This process's inotify instance: one descriptor, one poller, the watches per wd."""

    def __init__(self, libc, fd: int):
        self.libc = libc
        self.fd = fd
        self.pid = os.getpid()
        self.local = threading.local()  # a poller per thread: one poll object is not shareable
        self.lock = threading.Lock()
        #: wd -> the live watches that include it (weakly: a dropped watch releases its wds).
        self.by_wd: dict[int, weakref.WeakSet] = {}
        #: wds of dropped watches, released at the next arm (list.append is atomic).
        self.dropped: list[int] = []

    def add(self, path: str, mask: int) -> int:
        wd = self.libc.inotify_add_watch(self.fd, os.fsencode(path), mask)
        if wd < 0:
            raise OSError(ctypes.get_errno(), os.strerror(ctypes.get_errno()), path)
        return wd

    def pending(self) -> bool:
        """Notices are waiting to be read (a zero-timeout poll by this thread's poller)."""
        poller = getattr(self.local, "poller", None)
        if poller is None:
            poller = self.local.poller = select.poll()
            poller.register(self.fd, select.POLLIN)
        return bool(poller.poll(0))

    def release_dropped(self) -> None:
        """Stop watching the wds that no live watch shares any more (call with the lock held).

        Why not in ``Watch.__del__``: a finaliser may run inside :meth:`drain` on the same
        thread (a garbage collection), where taking the lock again would deadlock; and an
        inode watched again meanwhile gets the *same* wd back, which only a removal under the
        lock, after that arm registered, can tell apart."""
        while self.dropped:
            wd = self.dropped.pop()
            owners = self.by_wd.get(wd)
            if owners is None or len(owners) == 0:  # removing a gone wd again is harmless
                self.by_wd.pop(wd, None)
                self.libc.inotify_rm_watch(self.fd, wd)

    def drain(self) -> None:
        """Read every pending event and mark the watches it touched stale."""
        with self.lock:
            while True:
                try:
                    data = os.read(self.fd, 65536)
                except BlockingIOError:
                    return
                except OSError:  # the descriptor is unusable: trust nothing it watched
                    self._stale_all()
                    return
                if not data:
                    return
                offset = 0
                while offset + _EVENT.size <= len(data):
                    wd, _mask, _cookie, length = _EVENT.unpack_from(data, offset)
                    offset += _EVENT.size + length
                    if wd < 0:  # IN_Q_OVERFLOW: events were lost
                        self._stale_all()
                        continue
                    for watch in list(self.by_wd.get(wd, ())):
                        watch.stale = True

    def _stale_all(self) -> None:
        for owners in self.by_wd.values():
            for watch in list(owners):
                watch.stale = True


_notifier: _Notifier | None = None
_unavailable = False
_setup_lock = threading.Lock()


def _after_fork_in_child() -> None:
    """The parent's notices are not ours to read: drop the instance (its watches turn stale)."""
    global _notifier, _setup_lock
    old, _notifier = _notifier, None
    _setup_lock = threading.Lock()
    if old is not None:
        try:
            os.close(old.fd)
        except OSError:
            pass


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


def _load_libc():
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(None, use_errno=True)  # the C library Python runs on
        for name in ("inotify_init1", "inotify_add_watch", "inotify_rm_watch", "statfs"):
            getattr(libc, name)
    except (OSError, AttributeError):
        return None
    libc.inotify_add_watch.argtypes = (ctypes.c_int, ctypes.c_char_p, ctypes.c_uint32)
    libc.inotify_rm_watch.argtypes = (ctypes.c_int, ctypes.c_int)
    libc.statfs.argtypes = (ctypes.c_char_p, ctypes.c_void_p)
    return libc


def _get_notifier() -> _Notifier | None:
    global _notifier, _unavailable
    if _notifier is not None or _unavailable:
        return _notifier
    with _setup_lock:
        if _notifier is None and not _unavailable:
            libc = _load_libc()
            fd = libc.inotify_init1(IN_NONBLOCK | IN_CLOEXEC) if libc is not None else -1
            if fd < 0:
                # No inotify here, or the per-user instance limit is reached: stamps it is.
                # Only a missing facility is remembered; a limit may be lifted later.
                _unavailable = libc is None
                return None
            _notifier = _Notifier(libc, fd)
    return _notifier


def is_local(libc, path: str) -> bool:
    """``path`` is on a file system of :data:`LOCAL_FILE_SYSTEMS` (``statfs`` follows links)."""
    buf = ctypes.create_string_buffer(256)  # struct statfs is 120 bytes on 64-bit Linux
    if libc.statfs(os.fsencode(path), buf) != 0:
        return False
    f_type = ctypes.c_long.from_buffer(buf).value & 0xFFFFFFFF
    return f_type in LOCAL_FILE_SYSTEMS


class Watch:
    """Kernel notices on a directory and its files: :meth:`fresh` is True until any of them
    changes (or the process forked, or events were lost). Arm it *before* reading the files."""

    __slots__ = ("stale", "_notifier", "_wds", "__weakref__")

    def __init__(self, notifier: _Notifier, wds: tuple[int, ...]):
        self.stale = False
        self._notifier = notifier
        self._wds = wds

    def fresh(self) -> bool:
        n = self._notifier
        if n is not _notifier:  # forked, or the instance was replaced
            return False
        if n.pending() or n.lock.locked():  # pending notices, or another thread reading
            n.drain()
        return not self.stale

    def __del__(self):
        n = self._notifier
        if n is not None:
            n.dropped.extend(self._wds)  # released under the lock by the next arm


def arm(directory: str, files_of) -> Watch | None:
    """A :class:`Watch` on ``directory`` and on each file ``files_of(directory)`` lists (paths,
    listed after the directory's watch is in place, so a file added meanwhile is seen), or
    ``None`` when this system cannot give one (see the module docstring): the caller then
    checks stamps."""
    if not ENABLED:
        return None
    n = _get_notifier()
    if n is None:
        return None
    with n.lock:
        n.release_dropped()
        if not is_local(n.libc, directory):
            return None
        wds = []
        try:
            wds.append(n.add(directory, DIR_EVENTS))
            for p in files_of(directory):
                if not is_local(n.libc, p):
                    raise OSError(f"{p} is not on a local file system")
                wds.append(n.add(p, FILE_EVENTS))
        except OSError:  # vanished meanwhile, not local, or the watch limit: fall back
            n.dropped.extend(wds)
            n.release_dropped()
            return None
        watch = Watch(n, tuple(wds))
        for wd in wds:
            n.by_wd.setdefault(wd, weakref.WeakSet()).add(watch)
    return watch
