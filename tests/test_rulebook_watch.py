"""A cached rulebook follows every change of its files, with kernel change notices (inotify)
and with the stat key alone: edits right after a look-up, writes through a hard link, a
directory swapped in under the same path, a forked child, concurrent threads. And with notices
an unchanged directory costs one ``stat`` a look-up, not one per file (issue 24's budget)."""

from __future__ import annotations

import os
import re
import shutil
import sys
import threading
import time

import pytest

import xfuzzy_rrt.fuzzy.rulebook as rbmod
import xfuzzy_rrt.fuzzy.watch as watchmod

LINUX = sys.platform.startswith("linux")


def _copy(src, dst):
    shutil.copytree(src, dst)
    return dst


@pytest.fixture()
def shipped():
    return rbmod.default_rulebook_path()


@pytest.fixture(params=["kernel-watch", "stamps-only"])
def mode(request, monkeypatch):
    monkeypatch.setattr(watchmod, "ENABLED", request.param == "kernel-watch")
    return request.param


def _edit(fis):
    """Change one rule constant in place, keeping the size, and put the mtime back."""
    st = fis.stat()
    text = fis.read_text()
    m = re.search(r"then \w+ = (\S+)\n", text)
    old = m.group(1)
    new = old[:-1] + ("1" if old[-1] != "1" else "2")
    with open(fis, "r+") as f:  # in place: same inode
        f.write(text[:m.start(1)] + new + text[m.end(1):])
    os.utime(fis, ns=(st.st_atime_ns, st.st_mtime_ns))


def _sha(root):
    return rbmod.load_rulebook(root).sha256


def test_an_edit_right_after_a_look_up_is_seen(tmp_path, shipped, mode):
    root = _copy(shipped, tmp_path / "rb")
    before = rbmod.load_rulebook_cached(str(root))
    _edit(sorted(root.glob("*.fis"))[0])  # no pause: possibly within one timestamp tick
    after = rbmod.load_rulebook_cached(str(root))
    assert after.sha256 == _sha(root) != before.sha256


def test_a_write_through_a_hard_link_elsewhere_is_seen(tmp_path, shipped, mode):
    root = _copy(shipped, tmp_path / "rb")
    fis = sorted(root.glob("*.fis"))[1]
    other = tmp_path / "elsewhere"
    other.mkdir()
    os.link(fis, other / "alias.fis")
    before = rbmod.load_rulebook_cached(str(root))
    time.sleep(0.02)
    _edit(other / "alias.fis")
    after = rbmod.load_rulebook_cached(str(root))
    assert after.sha256 == _sha(root) != before.sha256


@pytest.mark.parametrize("how", ["parent renamed", "symlink flipped"])
def test_a_directory_swapped_in_under_the_same_path_is_seen(tmp_path, shipped, mode, how):
    _copy(shipped, tmp_path / "v1" / "rb")
    new = _copy(shipped, tmp_path / "v2" / "rb")
    _edit(sorted(new.glob("*.fis"))[0])
    edited = _sha(new)
    if how == "parent renamed":
        path = str(tmp_path / "live" / "rb")
        os.rename(tmp_path / "v1", tmp_path / "live")
    else:
        os.symlink(tmp_path / "v1", tmp_path / "live")
        path = str(tmp_path / "live" / "rb")
    before = rbmod.load_rulebook_cached(path)
    assert before.sha256 == _sha(tmp_path / "live" / "rb")
    if how == "parent renamed":
        os.rename(tmp_path / "live", tmp_path / "retired")
        os.rename(tmp_path / "v2", tmp_path / "live")
    else:
        os.symlink(tmp_path / "v2", tmp_path / "next")
        os.replace(tmp_path / "next", tmp_path / "live")  # the atomic flip deployments use
    after = rbmod.load_rulebook_cached(path)
    assert after.sha256 == edited == _sha(path) != before.sha256


def test_a_rulebook_file_replaced_by_an_atomic_save_is_seen(tmp_path, shipped, mode):
    root = _copy(shipped, tmp_path / "rb")
    fis = sorted(root.glob("*.fis"))[2]
    before = rbmod.load_rulebook_cached(str(root))
    tmp = root / "tmp.partial"
    shutil.copy2(fis, tmp)
    _edit(tmp)
    os.replace(tmp, fis)
    after = rbmod.load_rulebook_cached(str(root))
    assert after.sha256 == _sha(root) != before.sha256


@pytest.mark.skipif(not LINUX or not hasattr(os, "fork"), reason="inotify and fork: Linux")
def test_a_forked_child_sees_edits_made_after_the_fork_and_so_does_its_parent(tmp_path,
                                                                                 shipped):
    root = _copy(shipped, tmp_path / "rb")
    before = rbmod.load_rulebook_cached(str(root)).sha256
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # child: wait for the parent's edit, look up, report
        try:
            os.close(write)
            os.read(read, 1)
            sha = rbmod.load_rulebook_cached(str(root)).sha256
            with open(tmp_path / "child.txt", "w") as f:
                f.write(sha)
        finally:
            os._exit(0)
    os.close(read)
    _edit(sorted(root.glob("*.fis"))[0])
    parent_sees = rbmod.load_rulebook_cached(str(root)).sha256  # may drain the notices
    os.write(write, b"x")
    os.close(write)
    os.waitpid(pid, 0)
    expected = _sha(root)
    assert parent_sees == expected != before
    assert (tmp_path / "child.txt").read_text() == expected


def test_threads_looking_up_during_an_edit_all_see_it_once_it_is_done(tmp_path, shipped, mode):
    root = _copy(shipped, tmp_path / "rb")
    before = rbmod.load_rulebook_cached(str(root)).sha256
    edited = threading.Event()
    late = []

    def look():
        after = 0
        while after < 3:  # look up until three look-ups began after the edit was complete
            done = edited.is_set()
            sha = rbmod.load_rulebook_cached(str(root)).sha256
            if done:
                late.append(sha)
                after += 1

    threads = [threading.Thread(target=look) for _ in range(4)]
    for t in threads:
        t.start()
    time.sleep(0.05)
    _edit(sorted(root.glob("*.fis"))[0])
    edited.set()
    for t in threads:
        t.join()
    expected = _sha(root)
    assert expected != before
    assert late and set(late) == {expected}


@pytest.mark.skipif(not LINUX, reason="inotify is Linux's")
def test_with_kernel_notices_an_unchanged_directory_costs_one_stat_a_look_up(
        tmp_path, shipped, monkeypatch):
    monkeypatch.setattr(watchmod, "ENABLED", True)
    root = str(_copy(shipped, tmp_path / "rb"))
    first = rbmod.load_rulebook_cached(root)
    assert rbmod._STAT_CACHE[root].watch is not None  # this file system takes notices
    stats = []
    real = os.stat
    monkeypatch.setattr(os, "stat", lambda *a, **k: stats.append(a[0]) or real(*a, **k))
    for _ in range(5):
        assert rbmod.load_rulebook_cached(root) is first
    assert stats == [root] * 5


def test_a_file_system_without_local_notices_falls_back_to_stamps(tmp_path, shipped,
                                                                   monkeypatch):
    monkeypatch.setattr(watchmod, "ENABLED", True)
    monkeypatch.setattr(watchmod, "is_local", lambda libc, path: False)  # as NFS, 9p, FUSE
    root = _copy(shipped, tmp_path / "rb")
    before = rbmod.load_rulebook_cached(str(root))
    assert rbmod._STAT_CACHE[str(root)].watch is None
    time.sleep(0.05)
    _edit(sorted(root.glob("*.fis"))[0])
    after = rbmod.load_rulebook_cached(str(root))
    assert after.sha256 == _sha(root) != before.sha256


@pytest.mark.skipif(not LINUX, reason="inotify is Linux's")
def test_lost_notices_make_every_watch_stale(tmp_path, shipped, monkeypatch):
    monkeypatch.setattr(watchmod, "ENABLED", True)
    root = str(_copy(shipped, tmp_path / "rb"))
    rbmod.load_rulebook_cached(root)
    watch = rbmod._STAT_CACHE[root].watch
    assert watch.fresh()
    overflow = watchmod._EVENT.pack(-1, 0x4000, 0, 0)  # IN_Q_OVERFLOW carries wd -1
    real_read = os.read
    fed = []

    def read(fd, n):
        if fd == watchmod._notifier.fd and not fed:
            fed.append(1)
            return overflow
        return real_read(fd, n)

    monkeypatch.setattr(os, "read", read)
    watchmod._notifier.drain()
    assert not watch.fresh()


def _kernel_wds(fd):
    """The wds the kernel holds for this inotify descriptor (``/proc/self/fdinfo``)."""
    with open(f"/proc/self/fdinfo/{fd}") as f:
        return {int(m.group(1), 16) for m in re.finditer(r"inotify wd:([0-9a-f]+)", f.read())}


@pytest.mark.skipif(not LINUX, reason="inotify is Linux's")
def test_dropped_watches_release_their_kernel_watches(tmp_path, shipped, monkeypatch):
    monkeypatch.setattr(watchmod, "ENABLED", True)
    monkeypatch.setattr(rbmod, "MAX_CACHED_DIRS", 2)
    roots = [str(_copy(shipped, tmp_path / f"rb{i}")) for i in range(6)]
    wds = {}
    for r in roots:
        rbmod.load_rulebook_cached(r)
        wds[r] = rbmod._STAT_CACHE[r].watch._wds
    n = watchmod._notifier
    with n.lock:
        n.release_dropped()
    held = _kernel_wds(n.fd)
    for r in roots[:4]:  # evicted from the cache: their watches were dropped
        assert not set(wds[r]) & held and not set(wds[r]) & set(n.by_wd)
    for r in roots[4:]:
        assert len(wds[r]) == 1 + len(os.listdir(r)) - 1  # the directory, its files but history
        assert set(wds[r]) <= held
