"""The README's "From Python" example runs as written, from a folder that is not the
project (it finds its scenario through the package, as an installed wheel would)."""

import re
from pathlib import Path

PROJECT = Path(__file__).resolve().parents[1]


def test_the_readmes_python_example_runs_and_plans_certified_paths(monkeypatch, capsys,
                                                                    tmp_path):
    text = (PROJECT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    example = next(b for b in blocks if "load_shipped_default" in b)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(example, "README.md (From Python)", "exec"), namespace)
    assert all(r.success for r in namespace["results"])
    assert namespace["result"].success
    first = capsys.readouterr().out.splitlines()[0].split()
    assert first[:3] == ["True", "fuzzy-rrt", "goal-frame"]
