"""Tell the user once when numba starts compiling the planners (a cold on-disk cache).

Why: the first command after an install (or after a source change) compiles every kernel,
tens of seconds with no output at all. The CLI prints one line instead of looking hung. The
notice hangs on numba's own ``"numba:compile"`` event, which numba raises only when it really
compiles (a kernel loaded from its cache raises none), so a warm run prints nothing and no
guess about cache files is needed.

Worker processes forked after :func:`notify_first_compile` inherit the listener, and the
first kernel may compile only there (training workers). A flag in shared memory, inherited
with the fork, makes the notice appear once per command, whichever process compiles first.
"""

from __future__ import annotations

from typing import Callable


def notify_first_compile(callback: Callable[[], None]) -> Callable[[], None]:
    """Call ``callback()`` once, in whichever process of this command first compiles a kernel.

    Returns the function that removes the listener: a command run in-process (tests, scripts
    calling ``main()`` repeatedly) must not leave listeners behind that would each print the
    notice on a later command's compile."""
    import multiprocessing

    from numba.core import event

    flag = multiprocessing.Value("b", 0)  # shared with forked workers

    class _FirstCompile(event.Listener):
        def on_start(self, ev) -> None:
            with flag.get_lock():
                if flag.value:
                    return
                flag.value = 1
            callback()

        def on_end(self, ev) -> None:
            pass

    listener = _FirstCompile()
    event.register("numba:compile", listener)
    return lambda: event.unregister("numba:compile", listener)
