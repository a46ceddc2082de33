"""Write output files so that a failure never leaves a partial file behind.

Everything the CLI writes goes through :func:`atomic_path`: the caller writes to a temporary
file in the destination's folder, and only a successful exit of the ``with`` block renames it
into place (``os.replace`` is atomic on POSIX within one filesystem).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterator


@contextlib.contextmanager
def atomic_path(dest: str | os.PathLike[str], suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside *dest*; move it onto *dest* only if the block succeeds."""
    dest = Path(dest)
    dest.parent.mkdir(parents=True, exist_ok=True)
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{dest.name}.", suffix=suffix if suffix is not None else dest.suffix + ".tmp",
            dir=dest.parent,
        )
    except OSError as exc:  # name the caller's file, not the hidden temporary one
        raise OSError(exc.errno, exc.strerror, str(dest)) from None
    os.close(fd)
    tmp_path = Path(tmp)
    # mkstemp creates 0600 files; give outputs the usual permissions (respecting the umask).
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp_path, 0o666 & ~umask)
    try:
        yield tmp_path
        os.replace(tmp_path, dest)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp_path.unlink()
        raise


def write_text_atomic(dest: str | os.PathLike[str], text: str) -> None:
    """Write *text* (UTF-8, ``\\n`` newlines) to *dest* atomically."""
    with atomic_path(dest) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="\n")
