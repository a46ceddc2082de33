"""The planner registry: every planner label the tools accept, and what each planner can do.

Why one registry: the CLI's help and error text, :func:`~xfuzzy_rrt.planners.api.parse_planner`,
:func:`~xfuzzy_rrt.planners.api.plan_scenario`, the replay behind ``explain``, the benchmark
runner and the report all need to know the same few facts about a planner (does it take a
rulebook, does it record traces, does it stop at its first solution, how does a reproduce
command name it). Written once here, adding a planner is one :func:`register` call, and no
``if kind == ...`` chain elsewhere has to learn the new name (OMPL's planner factory, in small).

A registration is one *label form* (:class:`Planner`): an exact label (``rrt``, ``rrt:tuned``)
or a prefix ending in ``:`` that takes an argument (``fuzzy-rrt:RULEBOOK``, ``ompl:NAME``).
Several forms can run the same planner ``kind`` (``fuzzy-rrt`` and ``fuzzy-rrt:NAME``).
A label is found with one dict look-up (exact) or two (the text up to its first colon, colon
included): :func:`plan_scenario` parses its label on every call, a hot path.

This module imports nothing heavy (the console script builds its help text from it before numpy
is loaded): the built-in planners name their functions as ``"module:attribute"`` strings,
imported on first use and then kept on the registration.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Callable

#: ``fn(scenario, spec, rulebook, *, seed, max_iter, step_deg, goal_bias, trace, clearance_m,
#: max_time_s) -> PlanResult``: what :func:`~xfuzzy_rrt.planners.api.plan_scenario` calls.
PlanFn = Callable[..., Any]


def _resolve(ref):
    """A callable (or value) as given, or the one a ``"module:attribute"`` string names."""
    if ref is None or not isinstance(ref, str):
        return ref
    module, _, attr = ref.partition(":")
    return getattr(importlib.import_module(module), attr)


@dataclass(frozen=True)
class Planner:
    """One label form and the planner it runs (the registry's contract).

    - ``label``: the exact label (``"rrt:tuned"``), or a prefix ending in ``":"``
      (``"fuzzy-rrt:"``) whose argument ``arg`` names in help and error text (``"RULEBOOK"``).
    - ``kind``: the planner family the label runs (``PlannerSpec.kind``; ``rrt``,
      ``fuzzy-rrt``, ``fuzzy-rrt-connect``, ``ompl``, or the new planner's own name).
    - ``plan``: ``plan(scenario, spec, rulebook, *, seed, max_iter, step_deg, goal_bias,
      trace, clearance_m, max_time_s) -> PlanResult`` (a callable or ``"module:attr"``);
      it must label its result with ``spec.label`` and certify its path
      (:func:`~xfuzzy_rrt.planners.result.certified_result`).
    - ``parse``: ``parse(label, argument, where) -> rulebook directory or None``, validating
      the label fully (one :class:`~xfuzzy_rrt.errors.InputError` naming ``where``); ``None``:
      nothing to check. An exact label gets ``argument = None``.
    - ``takes_rulebook``: plans with a rulebook (``plan --rulebook``; the bench loads it).
    - ``traces``: records per-iteration traces (``plan --trace``; ``explain`` can replay it).
    - ``params``: the key of its parameter declaration in :data:`xfuzzy_rrt.planners.params.PARAMS`,
      or the declaration itself (a tuple of :class:`~xfuzzy_rrt.planners.params.Param`).
    - ``first_solution``: every run stops at its first solution (so the time to it is the
      planner's ``wall_s``); otherwise the result's ``stopped_by`` says.
    - ``core``: for a rulebook planner, its own function ``core(scenario, rulebook, seed=...,
      max_iter=..., trace=..., clearance_m=..., max_time_s=..., label=...)`` (what ``explain``
      replays); ``label`` names its result's ``planner``, ``planner_used`` is its own kind.
    - ``fits``: for a rulebook planner, ``fits(rulebook, scenario)`` raising one InputError
      when the rulebook cannot drive the problem (checked by ``bench`` before any run).
    - ``help``: its words in ``plan --planner``'s help (``None``: not listed there).
    - ``plan_rechecks``: its ``plan`` repeats every check of its ``parse``, with the same one
      line, so ``plan_scenario`` runs only the plan's once the label was accepted (``rrt:tuned``
      reads its tuned file once a call, as the default reads its rulebook's stamps once).
    - ``bind``: optional, ``bind(scenario, spec, rulebook, *, max_iter, step_deg, goal_bias,
      clearance_m) -> run | None``: what ``plan`` would do for a call without a trace or a time
      budget, as ``run(seed) -> PlanResult`` (the same result, bit for bit), which
      ``plan_scenario`` keeps for calls that pass the very same objects again; None when a
      later call must read something again (a file, a folder). ``None``: every call plans.
    - ``core_bind``: for a rulebook planner, ``core_bind(scenario, rulebook, *, max_iter,
      clearance_m, label) -> run``: ``core``'s run for every seed (what ``bind`` returns).
    """

    label: str
    kind: str
    plan: PlanFn | str
    arg: str | None = None
    parse: Callable[..., Any] | str | None = None
    takes_rulebook: bool = False
    traces: bool = False
    params: Any = None
    first_solution: bool = True
    core: Callable[..., Any] | str | None = None
    fits: Callable[..., Any] | str | None = None
    help: str | None = field(default=None, compare=False)
    plan_rechecks: bool = False
    bind: Callable[..., Any] | str | None = None
    core_bind: Callable[..., Any] | str | None = None

    def __post_init__(self) -> None:
        if self.arg is None and self.label.endswith(":"):
            raise ValueError(f"planner label {self.label!r}: a prefix needs an 'arg'")
        if self.arg is not None and (not self.label.endswith(":") or ":" in self.label[:-1]):
            raise ValueError(f"planner prefix {self.label!r} must end in its only ':'")

    @property
    def is_prefix(self) -> bool:
        return self.arg is not None

    @property
    def form(self) -> str:
        """How help and error text write it: ``rrt``, ``fuzzy-rrt:RULEBOOK``."""
        return self.label + (self.arg or "")

    @cached_property
    def plan_fn(self) -> PlanFn:
        return _resolve(self.plan)

    @cached_property
    def parse_fn(self):
        return _resolve(self.parse)

    @cached_property
    def core_fn(self):
        return _resolve(self.core)

    @cached_property
    def fits_fn(self):
        return _resolve(self.fits)

    @cached_property
    def bind_fn(self):
        return _resolve(self.bind)

    @cached_property
    def core_bind_fn(self):
        return _resolve(self.core_bind)

    def cli_name(self, label: str) -> str:
        """The ``plan --planner`` value that reruns *label* (of this form) with its rulebook
        passed as ``--rulebook``: the kind for a rulebook prefix (``fuzzy-rrt:NAME`` ->
        ``fuzzy-rrt``; Fuzzy-RRT refuses a Connect rulebook, so Connect stays Connect), else
        the label itself."""
        return self.kind if self.is_prefix and self.takes_rulebook else label


#: label (exact) -> registration, and prefix (``"fuzzy-rrt:"``) -> registration, in
#: registration order (which is the order of help and error text).
_EXACT: dict[str, Planner] = {}
_PREFIX: dict[str, Planner] = {}
_ORDER: list[Planner] = []


def register(planner: Planner) -> Planner:
    """Add a label form; ``ValueError`` when its label is taken. Returns it (for tests'
    :func:`unregister`)."""
    table = _PREFIX if planner.is_prefix else _EXACT
    if planner.label in table:
        raise ValueError(f"planner label {planner.form!r} is already registered")
    table[planner.label] = planner
    _ORDER.append(planner)
    return planner


def unregister(label: str) -> None:
    """Remove the form registered under ``label`` (exact label or prefix with its colon)."""
    planner = _EXACT.pop(label, None) or _PREFIX.pop(label)
    _ORDER.remove(planner)


def lookup(name: str) -> Planner | None:
    """The form a label belongs to, or ``None``; checks nothing about its argument except that
    there is one. Pure dict look-ups, no import: safe for argument parsing and for labels read
    back from old tables (whose rulebook directory may be gone)."""
    planner = _EXACT.get(name)
    if planner is not None:
        return planner
    head, colon, rest = name.partition(":")
    if colon and rest:
        return _PREFIX.get(head + ":")
    return None


def planners() -> tuple[Planner, ...]:
    """Every registered form, in registration order."""
    return tuple(_ORDER)


def exact_labels(**having) -> list[str]:
    """Exact labels whose attributes equal *having* (``traces=True``), in order."""
    return [p.label for p in _ORDER if not p.is_prefix
            and all(getattr(p, k) == v for k, v in having.items())]


def expected_text() -> str:
    """``rrt, fuzzy-rrt, ..., fuzzy-rrt:RULEBOOK or ompl:NAME``: every form, for an error line."""
    return either([p.form for p in _ORDER])


def either(labels: list[str], word: str = "or") -> str:
    """``a``, ``a or b``, ``a, b or c``."""
    return labels[0] if len(labels) == 1 else f"{', '.join(labels[:-1])} {word} {labels[-1]}"


def planner_help() -> str:
    """``plan --planner``'s help: the ``help`` words of every form that has them."""
    words = [p.help for p in _ORDER if p.help]
    return "Planner: " + (words[0] if len(words) == 1 else
                          f"{', '.join(words[:-1])}, or {words[-1]}.")


# --- The built-in planners (in the order their forms are listed in help and errors) -----------

_API = "xfuzzy_rrt.planners.api"
_FITS_FUZZY = "xfuzzy_rrt.planners.fuzzy_rrt:check_rulebook_fits"
_FITS_CONNECT = "xfuzzy_rrt.planners.connect:check_connect_rulebook"
_CORE_FUZZY = "xfuzzy_rrt.planners.fuzzy_rrt:plan_fuzzy_rrt"
_CORE_CONNECT = "xfuzzy_rrt.planners.connect:plan_fuzzy_rrt_connect"
_BIND_RRT = f"{_API}:bind_rrt_label"
_BIND_RULEBOOK = f"{_API}:bind_rulebook_label"
_CORE_BIND_FUZZY = "xfuzzy_rrt.planners.fuzzy_rrt:bind_fuzzy_rrt"
_CORE_BIND_CONNECT = "xfuzzy_rrt.planners.connect:bind_fuzzy_rrt_connect"

register(Planner("rrt", "rrt", f"{_API}:plan_rrt_label", params="rrt", help="rrt",
                 bind=_BIND_RRT))
register(Planner(
    "fuzzy-rrt", "fuzzy-rrt", f"{_API}:plan_rulebook_label", takes_rulebook=True, traces=True,
    params="fuzzy-rrt", core=_CORE_FUZZY, fits=_FITS_FUZZY, bind=_BIND_RULEBOOK,
    core_bind=_CORE_BIND_FUZZY,
    help="fuzzy-rrt (without --rulebook: goal-frame on one 2-joint arm, else fuzzy-rrt-connect "
         "with goal-frame-any; the JSON's planner_used says which ran)"))
register(Planner(
    "fuzzy-rrt-connect", "fuzzy-rrt-connect", f"{_API}:plan_rulebook_label",
    takes_rulebook=True, traces=True, params="fuzzy-rrt", core=_CORE_CONNECT,
    fits=_FITS_CONNECT, bind=_BIND_RULEBOOK, core_bind=_CORE_BIND_CONNECT))
register(Planner("rrt:tuned", "rrt", f"{_API}:plan_rrt_label", parse=f"{_API}:parse_tuned",
                 plan_rechecks=True, params="rrt", bind=_BIND_RRT))
register(Planner(
    "fuzzy-rrt:", "fuzzy-rrt", f"{_API}:plan_rulebook_label", arg="RULEBOOK",
    parse=f"{_API}:parse_rulebook_arg", takes_rulebook=True, traces=True, params="fuzzy-rrt",
    core=_CORE_FUZZY, fits=_FITS_FUZZY, bind=_BIND_RULEBOOK, core_bind=_CORE_BIND_FUZZY,
    help="fuzzy-rrt:NAME (a shipped rulebook) or fuzzy-rrt:DIR"))
register(Planner(
    "fuzzy-rrt-connect:", "fuzzy-rrt-connect", f"{_API}:plan_rulebook_label", arg="RULEBOOK",
    parse=f"{_API}:parse_rulebook_arg", takes_rulebook=True, traces=True, params="fuzzy-rrt",
    core=_CORE_CONNECT, fits=_FITS_CONNECT, bind=_BIND_RULEBOOK, core_bind=_CORE_BIND_CONNECT,
    help="fuzzy-rrt-connect[:NAME|:DIR] (two goal-frame trees; default rulebook goal-frame-any, "
         "any arm)"))
register(Planner(
    "ompl:", "ompl", f"{_API}:plan_ompl_label", arg="NAME", parse=f"{_API}:parse_ompl_arg",
    first_solution=False, bind=f"{_API}:bind_ompl_label", help="ompl:NAME (e.g. ompl:RRTConnect; optional 'ompl' extra)"))
