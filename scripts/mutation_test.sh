#!/usr/bin/env bash
# Mutation testing of the safety core (issue 11), on a throw-away copy of the tree.
#
# What is mutated: xfuzzy_rrt/geometry/collision.py and geometry/kinematics.py (all of them),
# planners/extend.py, and the path bookkeeping: tree.add_node, tree.extract_path and
# result.path_cost_deg. Which tests judge: tests/test_safety_bounds.py, test_collision.py and
# test_kinematics.py, the bound files named after each certified step (test_link_obstacle_bound,
# test_arm_arm_bound with the head-on two-arm case, test_self_pair_bound with self-collision),
# test_work_counter
# and the N-DOF files test_motion_bound_ndof.py and test_exact_geometry_ndof.py (override with
# MUTATION_TESTS="tests/a.py tests/b.py").
#
# Why a copy: mutmut 3 writes its instrumented sources into ./mutants/ of the directory it runs
# in, and mutmut skips decorated functions, i.e. every numba kernel. So the script copies the
# tree to a fresh directory, removes the `@nb.njit(...)` lines of the files under test there
# (the kernels run as plain Python anyway with NUMBA_DISABLE_JIT=1, so behaviour is unchanged),
# writes mutmut's [tool.mutmut] section into the *copy's* pyproject.toml and runs mutmut there.
# Nothing in the source tree is touched.
#
# Usage:   scripts/mutation_test.sh [WORKDIR]          (default: a new /tmp/xfuzzy-mutation.*)
#          scripts/mutation_test.sh --weaken F [WORKDIR]
#            instead of mutmut: make one certified step F times non-conservative in the copy
#            at a time -- (bound) M_k divided by F, (advance) the link-obstacle step
#            (c_k - clear) / M_k multiplied by F, (advance2) the same step in the
#            one-two-link-arm path that checks every 2-DOF edge, (armarm) the arm-arm bound M_k + M_m divided
#            by F, (armarm-max) replaced by max(M_k, M_m), (selfpair) the self-pair relative
#            bound divided by F, (advance-record, armarm-record, selfpair-record) the
#            link-obstacle step, the arm-arm bound and the self-pair step of a stop taken from
#            a node's stop record (3+ joints), (clearance) the user clearance held F times too leniently by
#            edge_free, (effective) by effective_margin, (minclear-speed, minclear-curvature)
#            the exact minimum clearance's first- and second-order lower bounds, (radius)
#            goal-frame clearance_deg
#            multiplied by F -- and run the test files NAMED AFTER that bound (numba on)
#            against each. Exit 0 only when every weakening fails its own tests. Try F = 1.05.
# Env:     PYTHON (default .venv/bin/python), MUTATION_JOBS (default 1), MUTATION_TESTS,
#          WEAKEN_VARIANTS (with --weaken: which of the variants above, default all),
#          MUTATION_MUTANTS (mutant name globs, default: the safety core as above).
# Needs:   mutmut >= 3.8 in that interpreter (.venv/bin/pip install mutmut).
# Output:  every surviving mutant with its diff, and a last line
#          "mutation score: K killed / N mutants = P %  (survived S, timeout T, other O)".
#          Exit status 0 when every mutant was killed, 1 otherwise.
set -euo pipefail

WEAKEN=""
if [ "${1:-}" = "--weaken" ]; then
  WEAKEN=${2:?--weaken needs a factor, e.g. 1.05}
  shift 2
fi
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
PY=${PYTHON:-$ROOT/.venv/bin/python}
MUTMUT=$(dirname "$PY")/mutmut
JOBS=${MUTATION_JOBS:-1}
WORK=${1:-$(mktemp -d /tmp/xfuzzy-mutation.XXXXXX)}
TESTS=${MUTATION_TESTS:-tests/test_safety_bounds.py tests/test_collision.py tests/test_kinematics.py tests/test_link_obstacle_bound.py tests/test_arm_arm_bound.py tests/test_self_pair_bound.py tests/test_work_counter.py tests/test_motion_bound_ndof.py tests/test_exact_geometry_ndof.py}
MUTANTS=${MUTATION_MUTANTS:-"xfuzzy_rrt.geometry.collision.* xfuzzy_rrt.geometry.kinematics.* xfuzzy_rrt.planners.extend.* xfuzzy_rrt.planners.tree.x_add_node__mutmut_* xfuzzy_rrt.planners.tree.x_extract_path__mutmut_* xfuzzy_rrt.planners.result.x_path_cost_deg__mutmut_*"}
FILES=(xfuzzy_rrt/geometry/collision.py xfuzzy_rrt/geometry/kinematics.py
       xfuzzy_rrt/planners/extend.py xfuzzy_rrt/planners/tree.py xfuzzy_rrt/planners/result.py)

[ -n "$WEAKEN" ] || [ -x "$MUTMUT" ] || { echo "error: $MUTMUT not found; run: $(dirname "$PY")/pip install mutmut" >&2; exit 2; }
case "$(cd "$WORK" 2>/dev/null && pwd || echo "$WORK")" in
  "$ROOT"|"$ROOT"/*) echo "error: the work directory must be outside $ROOT" >&2; exit 2 ;;
esac
mkdir -p "$WORK"

echo "copying $ROOT -> $WORK"
tar -C "$ROOT" --exclude=./.venv --exclude=./.git --exclude=./mutants --exclude=./reports \
    --exclude=__pycache__ --exclude='*.nbi' --exclude='*.nbc' --exclude=.hypothesis \
    --exclude=.pytest_cache -cf - . | tar -C "$WORK" -xf -
# tests/conftest.py finds the shared scenarios at <project>/../shared; mutmut's project is
# WORK/mutants, so WORK/shared must point at them.
if [ -d "$ROOT/../shared" ] && [ ! -e "$WORK/shared" ]; then
  ln -s "$(cd "$ROOT/../shared" && pwd)" "$WORK/shared"
fi

cd "$WORK"
if [ -n "$WEAKEN" ]; then
  status=0
  for variant in ${WEAKEN_VARIANTS:-bound advance advance2 armarm armarm-max selfpair advance-record armarm-record selfpair-record clearance effective minclear-speed minclear-curvature radius}; do
    for f in xfuzzy_rrt/geometry/collision.py xfuzzy_rrt/geometry/clearance.py xfuzzy_rrt/planners/goal_frame.py; do
      cp "$ROOT/$f" "$f"
    done
    find xfuzzy_rrt -name '*.nbi' -delete -o -name '*.nbc' -delete
    named=$("$PY" - "$variant" "$WEAKEN" <<'PYEOF'
"""Weaken one certified step in the copy; print the test files named after that bound."""
import sys
from pathlib import Path

variant, factor = sys.argv[1], sys.argv[2]
collision = "xfuzzy_rrt/geometry/collision.py"
F = factor
# the arm-arm bound's line with the lines before it, which tell the measured stop
# (_edge_stop writes its value to a record) from one taken from a record (_stored_stop)
ARMARM = ("{value}\n                        col += 1\n                        if not d < np.inf:\n"
          "                            return False, cmin, ds\n"
          "                        cmin, ds = _fold(d, {mkm}, clear, cmin, ds)\n")
# the self-pair step after a value read from a record (one arm's non-adjacent links)
SELF_STEP = ("                    if not d < np.inf:\n                        return False, cmin, ds\n"
             "                    cmin, ds = _fold(d, msf[k, m], clear, cmin, ds)\n")
file, old, new, tests = {
    # M_k itself (every step that uses it: link-obstacle, arm-arm, self pairs) ...
    "bound": (collision,
              "        mk += abs(math.radians(qb_deg[j] - qa_deg[j])) * tail\n    return mk\n",
              f"        mk += abs(math.radians(qb_deg[j] - qa_deg[j])) * tail\n    return mk / {F}\n",
              "tests/test_link_obstacle_bound.py tests/test_safety_bounds.py"),
    # ... the per-link obstacle step (c_k - clear) / M_k ...
    # (the step is computed by _fold, shared by every element of both kinds of stop: each
    # variant weakens the bound one call site hands it, as if that step were F times longer)
    "advance": (collision, "\n                cmin, ds = _fold(ck, mks[k], clear, cmin, ds)\n",
                f"\n                cmin, ds = _fold(ck, mks[k] / {F}, clear, cmin, ds)\n",
                "tests/test_link_obstacle_bound.py tests/test_margins.py"),
    # ... the same step taken from a node's stop record (_stored_stop: an edge's first and
    # last stop on 3+ joints in the planners) ...
    "advance-record": (collision, "\n            cmin, ds = _fold(ck, mks[k], clear, cmin, ds)\n",
                       f"\n            cmin, ds = _fold(ck, mks[k] / {F}, clear, cmin, ds)\n",
                       "tests/test_stop_records.py"),
    # ... the same step in the one-two-link-arm path (edge_free_two_link, every 2-DOF edge) ...
    "advance2": (collision, "_fold(c{k}, m{k}, clear, ",
                 f"_fold(c{{k}}, m{{k}} / {F}, clear, ",
                 "tests/test_link_obstacle_bound.py tests/test_margins.py"),
    # ... the arm-arm bound M_k + M_m, weakened by F or replaced by max (issue 22) ...
    "armarm": (collision, ARMARM.format(value="rows[r, col] = d", mkm="mka + mks[m]"),
               ARMARM.format(value="rows[r, col] = d", mkm=f"(mka + mks[m]) / {F}"),
               "tests/test_arm_arm_bound.py"),
    "armarm-max": (collision, ARMARM.format(value="rows[r, col] = d", mkm="mka + mks[m]"),
                   ARMARM.format(value="rows[r, col] = d", mkm="max(mka, mks[m])"),
                   "tests/test_arm_arm_bound.py"),
    "armarm-record": (collision, ARMARM.format(value="d = rows[r, col]", mkm="mka + mks[m]"),
                      ARMARM.format(value="d = rows[r, col]", mkm=f"(mka + mks[m]) / {F}"),
                      "tests/test_stop_records.py"),
    # ... the self-pair step taken from a stop record ...
    "selfpair-record": (collision, "d = rows[r, col]\n                    col += 1\n" + SELF_STEP,
                        "d = rows[r, col]\n                    col += 1\n" + SELF_STEP.replace(
                            "msf[k, m], clear", f"msf[k, m] / {F}, clear"),
                        "tests/test_stop_records.py"),
    # ... the self-pair relative bound ...
    "selfpair": (collision, "    return link_motion_bound(links, qa_deg, qb_deg, m, k + 1)\n",
                 f"    return link_motion_bound(links, qa_deg, qb_deg, m, k + 1) / {F}\n",
                 "tests/test_self_pair_bound.py"),
    # ... the user clearance (issue 18) held F times too leniently by edge_free ...
    "clearance": (collision, "    clear = P.clearance\n",
                  f"    clear = P.clearance / {F}\n    margin = margin - (P.clearance - clear)\n",
                  "tests/test_margins.py"),
    # ... or by the margin every planner is given for it ...
    "effective": (collision, "    return CERT_MARGIN_M + float(clearance_m)\n",
                  f"    return CERT_MARGIN_M + float(clearance_m) / {F}\n",
                  "tests/test_margins.py"),
    # ... and clearance_deg, the goal-frame input that claims a certified joint-space radius.
    # ... the exact minimum clearance's lower bounds (geometry/clearance.py): the element
    # speed (first order) and the curvature constant K (second order, flat minima) ...
    "minclear-speed": ("xfuzzy_rrt/geometry/clearance.py",
                       "    lb1 = 0.5 * (c0 + c1 - v * width)\n",
                       f"    lb1 = 0.5 * (c0 + c1 - v / {F} * width)\n",
                       "tests/test_flat_minimum_clearance.py"),
    "minclear-curvature": ("xfuzzy_rrt/geometry/clearance.py",
                           "    half_k = 0.5 * (acc + v * v / d) * width * width  # K width² / 2\n",
                           f"    half_k = 0.5 * (acc + v * v / d) * width * width / {F}\n",
                           "tests/test_flat_minimum_clearance.py"),
    "radius": ("xfuzzy_rrt/planners/goal_frame.py",
               "    deg_per_m = math.degrees(1.0) / problem_lever(P)\n",
               f"    deg_per_m = math.degrees(1.0) / problem_lever(P) * {F}\n",
               "tests/test_clearance_radius.py"),
}[variant]
path = Path(file)
text = path.read_text()
# "{k}" stands for each link of the two-link path (0 and 1); every other pattern appears once,
# or once per edge-check path (the user clearance is read by both): all of them are weakened.
pairs = ([(old.replace("{k}", str(k)), new.replace("{k}", str(k))) for k in (0, 1)]
         if "{k}" in old else [(old, new)])
for o, n in pairs:
    if text.count(o) < 1:
        sys.exit(f"error: cannot find the {variant} code to weaken in {path}")
    text = text.replace(o, n)
path.write_text(text)
print(tests)
PYEOF
)
    echo "== $variant weakened by a factor $WEAKEN (tests named after it: $named):"
    # shellcheck disable=SC2086
    if PYTHONPATH="$WORK" nice -n 10 "$PY" -m pytest -q -p no:cacheprovider -p no:randomly \
        $named > weaken-$variant.log 2>&1; then
      echo "NOT CAUGHT: $named pass with the $variant weakened by $WEAKEN"
      status=1
    else
      for f in $named; do
        n=$(grep -cE "^FAILED $f::" weaken-$variant.log || true)
        echo "  $f: $n failing, e.g. $(grep -m1 -E "^FAILED $f::" weaken-$variant.log | sed -E 's/^FAILED [^:]*:://; s/ - .*//' || true)"
      done
      echo "caught (log: $WORK/weaken-$variant.log)"
    fi
  done
  exit $status
fi
"$PY" - "${FILES[@]}" <<'EOF'
"""Drop the numba decorators of the files under test (mutmut skips decorated functions)."""
import re
import sys
from pathlib import Path

for name in sys.argv[1:]:
    path = Path(name)
    text = path.read_text()
    new, n = re.subn(r"(?m)^@nb\.njit\([^)]*\)\n", "", text)
    if n == 0 and "@nb.njit" in text:
        sys.exit(f"error: could not strip the numba decorators of {name}")
    path.write_text(new)
    print(f"  {name}: {n} numba decorators removed")
EOF

"$PY" - "$TESTS" "${FILES[@]}" <<'EOF'
"""Append the [tool.mutmut] section to the copy's pyproject.toml."""
import json
import sys
from pathlib import Path

tests = sys.argv[1].split()
files = sys.argv[2:]
section = "\n".join([
    "",
    "[tool.mutmut]",
    'source_paths = ["xfuzzy_rrt"]',
    f"only_mutate = {json.dumps(files)}",
    f"pytest_add_cli_args_test_selection = {json.dumps(tests)}",
    'pytest_add_cli_args = ["-p", "no:cacheprovider", "-p", "no:randomly", "--hypothesis-seed=0", "-q"]',
    "use_git_change_detection = false",
    # A mutant that never lets the advancement reach s = 1 hangs: give up after 5x the clean
    # run's time (counted as detected, see below) rather than mutmut's default 15x.
    "timeout_multiplier = 5.0",
    "",
])
with open("pyproject.toml", "a") as fh:
    fh.write(section)
EOF

export NUMBA_DISABLE_JIT=1
export PYTHONHASHSEED=0
# shellcheck disable=SC2086
nice -n 10 "$MUTMUT" run --max-children "$JOBS" $MUTANTS || true

"$MUTMUT" results --all true > mutmut-results.txt
"$PY" - "$MUTMUT" $MUTANTS <<'EOF'
"""Score the mutants matched by the globs; show the diff of every survivor."""
import fnmatch
import subprocess
import sys
from collections import Counter

mutmut, patterns = sys.argv[1], sys.argv[2:]
statuses = {}
for line in open("mutmut-results.txt"):
    name, _, status = line.strip().rpartition(": ")
    if name and any(fnmatch.fnmatch(name, p) for p in patterns):
        statuses[name] = status
count = Counter(statuses.values())
survivors = sorted(n for n, s in statuses.items() if s != "killed")
for name in survivors:
    print(f"--- {name}: {statuses[name]}")
    print(subprocess.run([mutmut, "show", name], capture_output=True, text=True).stdout)
total = len(statuses)
# A mutant that makes the tests hang (e.g. an advancement that never reaches s = 1) is
# detected too: timeouts count as killed.
killed = count["killed"] + count["timeout"]
other = total - killed - count["survived"]
print(f"by status: {dict(count)}")
print(f"mutation score: {killed} killed / {total} mutants = "
      f"{100.0 * killed / max(total, 1):.1f} %  (survived {count['survived']}, "
      f"timeouts among killed {count['timeout']}, other {other})")
sys.exit(0 if total and killed == total else 1)
EOF
