"""The docs stay true: the settings tables match the config dataclasses, the Python examples run, the links resolve."""

import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_settings_tables_are_up_to_date():
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / "gen_settings.py"), "--check"], capture_output=True, text=True
    )
    assert done.returncode == 0, (
        f"run `python docs/gen_settings.py` to refresh docs/algorithms.md\n{done.stdout}{done.stderr}"
    )


def _python_blocks():
    """Every ```python block of the README and docs/*.md, as pytest params named FILE#N."""
    params = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        blocks = re.findall(r"^```python\n(.*?)^```", path.read_text(), flags=re.DOTALL | re.MULTILINE)
        for i, code in enumerate(blocks, 1):
            params.append(pytest.param(code, id=f"{path.relative_to(ROOT)}#{i}"))
    return params


@pytest.mark.parametrize("code", _python_blocks())
def test_documented_python_examples_run(code, tmp_path, monkeypatch):
    """The examples run as written, except that training budgets are cut to 2 000 samples."""
    if "stable_baselines3" in code:
        pytest.importorskip("stable_baselines3")
    if "pettingzoo" in code or "parallel_env" in code:
        pytest.importorskip("pettingzoo")  # an optional extra (multiagent)
    if "WandbCallback" in code:  # offline, into tmp_path: wandb set up anew reads where
        wandb = pytest.importorskip("wandb", reason='the W&B example needs pip install "pamdp[wandb]"')
        monkeypatch.setenv("WANDB_MODE", "offline")
        monkeypatch.setenv("WANDB_DIR", str(tmp_path))
        wandb.teardown()
    code = re.sub(r"\.learn\((total_timesteps=)?([\d_]+)", r".learn(\1min(\2, 2_000)", code)
    monkeypatch.chdir(tmp_path)  # examples write runs/, GIFs and checkpoints where they run
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an example that registers an env again
        exec(compile(code, "<doc example>", "exec"), {"__name__": "__doc_example__"})


def _anchor(heading: str) -> str:
    """GitHub's anchor for a markdown heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"`|\*\*|\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip()).lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _prose(path: Path) -> str:
    """A markdown page without its fenced code blocks (whose ``# comments`` are no headings, ``](x)`` no links)."""
    return re.sub(r"^```.*?^```", "", path.read_text(), flags=re.DOTALL | re.MULTILINE)


def _anchors(path: Path) -> set[str]:
    found: set[str] = set()
    for heading in re.findall(r"^#{1,6} (.+)$", _prose(path), flags=re.MULTILINE):
        base, n = _anchor(heading), 0
        while (anchor := base if n == 0 else f"{base}-{n}") in found:  # repeated headings get -1, -2, ...
            n += 1
        found.add(anchor)
    return found


def test_relative_links_and_their_anchors_resolve():
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), *sorted((ROOT / "benchmarks").glob("*.md"))]
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^)\s]+)\)", _prose(page)):
            if re.match(r"[a-z]+:", target):  # https:, mailto:
                continue
            file, _, anchor = target.partition("#")
            dest = (page.parent / file).resolve() if file else page
            if not dest.exists():
                broken.append(f"{page.relative_to(ROOT)}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
                broken.append(f"{page.relative_to(ROOT)}: {target} (no such heading in {dest.name})")
    assert not broken, "\n".join(broken)


def test_the_suite_table_in_the_results_page_is_the_generated_one():
    results = ROOT / "docs" / "results.md"
    generated = (ROOT / "docs" / "results" / "benchmark-suite" / "suite.md").read_text()
    assert generated in results.read_text()


def test_the_generated_tables_of_the_docs_are_up_to_date():
    """The commands, algorithms, experiments and env ids tables (docs/cli.md, docs/environments.md) are the code's."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / "gen_cli_tables.py"), "--check"], capture_output=True, text=True
    )
    assert done.returncode == 0, f"run `python docs/gen_cli_tables.py`\n{done.stdout}{done.stderr}"


def test_the_results_tables_are_the_ones_the_committed_summaries_give():
    """Issue 44: docs/results.md's tables of the benchmark suite (and suite.md, suite-finals.json beside its figures)
    are what docs/gen_results.py makes of the summaries in docs/results/summaries."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "docs" / "gen_results.py"), "--check"], capture_output=True, text=True
    )
    assert done.returncode == 0, f"run `python docs/gen_results.py`\n{done.stdout}{done.stderr}"
    text = (ROOT / "docs" / "results.md").read_text()
    for name in ("suite", "suite-stats", "suite-aggregate", "suite-improvement", "suite-efficiency"):
        assert f"<!-- results:{name} start -->" in text


def test_committed_summaries_are_small_and_name_no_machines_path():
    summaries = sorted((ROOT / "docs" / "results" / "summaries").rglob("*.json"))
    assert len(summaries) >= 70
    for path in summaries:
        text = path.read_text()
        assert len(text) < 20_000, path
        assert "/root/" not in text and "/home/" not in text and "/tmp/" not in text, path


def test_the_readme_names_every_algorithm_and_experiment_of_the_code():
    from pamdp.algos import ALGORITHMS
    from pamdp.experiments import available_experiments

    readme = (ROOT / "README.md").read_text()
    assert [f"`{name}`" for name in [*ALGORITHMS, *available_experiments()] if f"`{name}`" not in readme] == []


def test_no_doc_cites_files_a_user_of_the_package_never_has():
    """The docs and the command's own modules cite the public sources, not the project's private specs."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    code = [ROOT / "src" / "pamdp" / "cli.py", *sorted((ROOT / "src" / "pamdp" / "experiments").rglob("*.py"))]
    citing = [str(p.relative_to(ROOT)) for p in [*pages, *code] if "shared/specs" in p.read_text()]
    assert citing == []


def _documented_commands():
    """Every ``pamdp ...`` line of a ```bash block of the README and docs/*.md, as pytest params named FILE:LINE."""
    params = []
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        lang = None  # the open block's language; None outside blocks
        lines = path.read_text().replace("\\\n", " ").splitlines()
        for number, line in enumerate(lines, 1):
            if line.startswith("```"):
                lang = line[3:].strip() if lang is None else None
            elif lang == "bash" and line.startswith("pamdp "):
                params.append(pytest.param(line, id=f"{path.relative_to(ROOT)}:{number}"))
    return params


def _argv(line: str, runs: Path) -> list[str]:
    """A documented command's arguments, with ``$PAMDP_RUNS`` (where the project keeps its runs) in ``runs`` and
    a trailing ``...`` (settings left out of the line) dropped."""
    import shlex

    argv = shlex.split(line.replace("$PAMDP_RUNS", str(runs)), comments=True)[1:]
    return argv[:-1] if argv[-1] == "..." else argv


@pytest.mark.parametrize("line", _documented_commands())
def test_documented_commands_are_valid_and_the_short_ones_run(line, tmp_path, monkeypatch, capsys):
    """Issue 46: every documented command parses as the code has it; a reproduce command's experiment, runs and seeds
    exist (its --status, which trains nothing, is run); a render of an env id runs as written. Commands that train
    for minutes are checked, not run."""
    from pamdp.cli import build_parser, main

    monkeypatch.chdir(tmp_path)
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:  # the files the docs show, written out
        for name, text in re.findall(r"^```toml\n# ([\w.-]+\.toml)\b.*?\n(.*?)^```", path.read_text(), re.S | re.M):
            (tmp_path / name).write_text(text)
    argv = _argv(line, tmp_path / "runs")
    if argv[0] == "reproduce" and any(a.startswith(("benchmarks/", "docs/")) for a in argv[1:]):
        monkeypatch.chdir(ROOT)  # an experiment file or the summaries of the repository, named from its root
    args = build_parser().parse_args(argv)
    if args.command == "reproduce":
        status = [a for a in argv if a not in ("--backend", "ray")]
        assert main([*status, "--status"] if "--status" not in status else status) == 0, capsys.readouterr().err
    elif args.command == "render" and args.source.startswith("pamdp/"):  # an env id: random actions
        assert main(argv) == 0, capsys.readouterr().err
        assert Path(args.out).exists()
