"""Validated plan set-ups remembered between calls.

Why: on a 2-DOF problem a planner's kernel often runs for well under 0.1 ms, and what a call
checks and builds before it (the arm's DOF, the clearance against the start and goal, every
parameter's range, the rulebook against the arms, the kernel's mode, its problem record) costs
tens of microseconds of Python. A library loop, a benchmark or ``evaluate`` plans the same
scenario object with the same settings many times (seeds), so the result of those checks is
remembered, keyed on exactly what the checks read.

When a remembered set-up is used:

- the same scenario *object* (scenarios are frozen), found through a weak reference, so a
  recycled ``id`` never matches a dead scenario's entry;
- the same settings, equal in value *and* type (``True`` is not ``1``, ``-0.0`` is not
  ``0.0``, ``1`` is not ``1.0``): :func:`exact` builds the key;
- the caller checks that the rulebook it resolves now is the very object the set-up was
  built for (an edited rulebook directory loads as a new object: ``load_rulebook_cached``).

A call that passes the very same scenario, setting and loaded-rulebook objects as one of the
planner's last few finds that set-up without building the key (:func:`last_call`): the loop
case, where building the key was most of the look-up's cost.

Errors are never remembered: only a set-up whose checks all passed is stored, so a call with
bad inputs runs the checks and raises the same one-line error every time. The memo is bounded
(:data:`MAX_ENTRIES`, oldest dropped first; an entry also goes when its scenario does) and shared by threads; set-ups are immutable, and
what a call mutates (the tree, the work counter) is never part of one.
"""

from __future__ import annotations

import math
import weakref
from typing import Any, Callable, Hashable

#: Set-ups kept (each a few small arrays and references to shared, immutable objects; an
#: entry goes with its scenario). Why this many: the memo is used in a cycle (every problem x
#: planner x setting, then the next seed), and a cycle one longer than the memo misses every
#: time (128 made 48 problems x 3 planners re-check every call: +60 us each).
MAX_ENTRIES = 4096
_memo: dict[Hashable, tuple[Any, Any]] = {}


class _Unhashable:
    """A key part that equals nothing else: a setting that cannot be a key never hits."""

    __slots__ = ()


def exact(value: Any) -> Hashable:
    """A key for ``value`` that tells apart values Python calls equal but the checks do not:
    its type goes in, and a float's sign (``-0.0`` and ``0.0`` print differently in a result's
    ``params``). NaN keys never match (NaN is never equal to itself, and a NaN setting never
    passes the checks anyway)."""
    if value is None:
        return None
    kind = type(value)
    if kind is float:
        return kind, value, math.copysign(1.0, value)
    try:
        hash(value)
    except TypeError:
        return _Unhashable()
    return kind, value


def rulebook_token(rulebook: Any) -> Hashable:
    """A key for the ``rulebook`` argument as given: ``None``, a path (as a string) or a loaded
    rulebook's identity. Only narrows the search: the caller still compares the resolved
    rulebook object with the set-up's."""
    if rulebook is None or type(rulebook) is str:
        return rulebook
    if hasattr(rulebook, "__fspath__"):
        return "path", rulebook.__fspath__()
    return "object", id(rulebook)


def lookup(key: Hashable, scenario: Any) -> Any | None:
    """The set-up remembered for ``key`` if it was made for this very ``scenario``, else None."""
    hit = _memo.get(key)
    if hit is None or hit[0]() is not scenario:
        return None
    return hit[1]


def remember(key: Hashable, scenario: Any, setup: Any, store: dict | None = None,
             limit: int = MAX_ENTRIES) -> None:
    """Keep ``setup`` for ``key`` as ``(weak reference to scenario, setup)`` in ``store`` (this
    memo by default; ``api._LANES`` keeps its runs the same way), the oldest entries dropped
    beyond ``limit``, an entry dropped when its scenario dies (nothing is kept for a scenario
    without weak references)."""
    store = _memo if store is None else store
    try:
        # ``_forget`` is bound here, not looked up when the scenario dies: a scenario that
        # outlives the module (a script's global, freed at interpreter exit after the modules'
        # names are cleared) printed "Exception ignored ... 'NoneType' object is not callable"
        ref = weakref.ref(scenario, lambda r, k=key, s=store, forget=_forget: forget(s, k, r))
    except TypeError:
        return
    store.pop(key, None)  # re-inserted last: the newest
    store[key] = (ref, setup)
    while len(store) > limit:
        try:
            del store[next(iter(store))]
        except (KeyError, StopIteration, RuntimeError):  # another thread trimmed it first
            break


def _forget(store: dict, key: Hashable, ref: weakref.ref) -> None:
    """The scenario of ``key``'s entry died: drop the entry if it is still that one's."""
    hit = store.get(key)
    if hit is not None and hit[0] is ref:
        store.pop(key, None)


def remembered(key: Hashable, scenario: Any, prepare: Callable[[], Any], rulebook: Any = None,
               resolve: Callable[[Any], Any] | None = None) -> Any:
    """The set-up remembered for ``key`` and this ``scenario``, else ``prepare()``, remembered.
    ``prepare`` runs every check, so an error is raised, not remembered.

    With ``resolve`` (a planner whose set-up holds the resolved rulebook ``rb``): valid only
    while the ``rulebook`` argument resolves to that very object. A loaded rulebook given as the
    argument *is* the one it resolves to (and the entry keeps it alive, so its ``id`` in the key
    cannot be reused), so it is compared directly; a directory or ``None`` is resolved again (an
    edited directory loads as a new object). Why no callback: with the caches cold (a
    benchmark's other planners, a program between plans) each Python call of a plan costs
    microseconds, and the default's set-up took ~10 us more than the tuned RRT's."""
    hit = lookup(key, scenario)
    if hit is not None and (resolve is None or hit.rb is rulebook or resolve(rulebook) is hit.rb):
        return hit
    setup = prepare()
    remember(key, scenario, setup)
    return setup


#: Per planner, its last set-ups with the very objects they were asked for (most recent first):
#: ``(weak reference to the scenario, settings tuple, set-up)``.
_last: dict[str, list[tuple[Any, tuple, Any]]] = {}

#: Set-ups :func:`last_call` keeps per planner: more than one, so that two labels of one planner
#: called in turn (``rrt`` and ``rrt:tuned`` in the fair protocol) both hit.
LAST_PER_SITE = 4


def last_call(site: str, scenario: Any, settings: tuple) -> Any | None:
    """A set-up *site* used recently, if this call passes the very same scenario and setting
    *objects* (``is``, one by one), else None.

    Why: building the exact key (an :func:`exact` call per setting) and looking it up cost
    ~29 us of a call that starts with cold caches and ~1 us warm, for every planner
    (docs/peer-measurements.md, twelfth session); a loop of plans passes the same objects every
    time. Identical objects are equal in value and type, so a hit is exactly a hit of the key;
    a loaded rulebook among the settings must be the same object too. Anything else (another
    object of equal value, a rulebook given as a directory or ``None``, which must be resolved
    again) misses and takes the key."""
    for ref, old, setup in _last.get(site, ()):
        if ref() is scenario and len(old) == len(settings) and \
                all(a is b for a, b in zip(old, settings)):
            return setup
    return None


def keep_last(site: str, scenario: Any, settings: tuple, setup: Any) -> None:
    """Remember *setup* among *site*'s last (see :func:`last_call`; at most
    :data:`LAST_PER_SITE`, the oldest dropped)."""
    try:
        ref = weakref.ref(scenario)
    except TypeError:
        return
    _last[site] = [(ref, settings, setup), *_last.get(site, ())][:LAST_PER_SITE]


def set_up(site: str, scenario: Any, prepare: Callable[..., Any], settings: tuple,
           resolve: Callable[[Any], Any] | None = None) -> Any:
    """``prepare(scenario, *settings, None)`` (a planner's checks without a time budget),
    remembered: what every planner's call asks for its set-up, in one place.

    A call that passes the very objects of one of *site*'s last calls finds it without a key
    (:func:`last_call`); otherwise the exact key -- *site*, the scenario's ``id`` and each
    setting through :func:`exact` -- is looked up (:func:`remembered`). With ``resolve``, the
    first setting is the rulebook argument: it goes into the key as :func:`rulebook_token`, and
    only a loaded rulebook is matched by identity (a directory or ``None`` must be resolved
    again)."""
    rulebook = settings[0] if resolve is not None else None
    by_identity = resolve is None or hasattr(rulebook, "compiled")
    if by_identity:
        setup = last_call(site, scenario, settings)
        if setup is not None:
            return setup
    if resolve is None:
        key = (site, id(scenario), *(exact(v) for v in settings))
    else:
        key = (site, id(scenario), rulebook_token(rulebook), *(exact(v) for v in settings[1:]))
    setup = remembered(key, scenario, lambda: prepare(scenario, *settings, None), rulebook,
                       resolve)
    if by_identity:
        keep_last(site, scenario, settings, setup)
    return setup


def clear() -> None:
    """Forget every set-up (tests; nothing else needs it)."""
    _memo.clear()
    _last.clear()
