"""The documentation runs as written: README.md and docs/*.md.

Every ```python block is a script: it is written to ``script.py`` in an empty temporary
folder and run as ``python script.py`` would run it (``__name__ == "__main__"``, the
script's folder first on sys.path, a fresh namespace), so a block a reader saves and runs
behaves here as it does there, ``if __name__ == "__main__":`` guards included.  A block
that must not run says so and why: ```python no-run: <reason>.  In the ```bash blocks,
every line that starts with ``gcmh `` runs, except those that need a running scheduler at
an address (``tcp://``); ``gcmh-app`` lines need a display, so only their options are
checked here, against ``gcmh-app --help`` (tests/app runs the app's modes).

One child interpreter runs all the scripts and command lines, one after the other, each in
its own folder (the command lines given to the console script's ``gcmh_core.cli.main``):
a fresh interpreter per block would load numba's kernel cache again every time, about a
second each.  ``test_a_script_runs_as_python_runs_it`` holds that child to what ``python
script.py`` does, and that the installed ``gcmh`` runs through bash is checked once.

Every link of these pages leads to a file (and, for a page, to one of its headings), and
docs/examples.md is what docs/make_examples.py prints.
"""

import importlib.util
import json
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
BIN = Path(sys.executable).parent  # gcmh and gcmh-app are installed beside this interpreter
FENCE = re.compile(r"^```([^`\n]*)\n(.*?)^```[ \t]*$", flags=re.S | re.M)
# what a fence may say (an info string it does not know is a typo: ```py would silently not run)
INFOS = ("python", "python no-run", "bash", "text", "")


@dataclass(frozen=True)
class Block:
    page: str   # relative to the repository
    line: int   # of the opening fence
    info: str
    code: str


def _blocks() -> list[Block]:
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for m in FENCE.finditer(text):
            out.append(Block(str(page.relative_to(ROOT)), text.count("\n", 0, m.start()) + 1, m.group(1).strip(),
                             m.group(2)))
    return out


BLOCKS = _blocks()
SCRIPTS = [b for b in BLOCKS if b.info == "python"]


def _lines(prefix: str) -> list[tuple[str, str]]:
    """(page:line, command) for each line of a ```bash block that runs ``prefix``."""
    out = []
    for b in BLOCKS:
        if b.info == "bash":
            for i, line in enumerate(b.code.splitlines(), start=b.line + 1):
                line = line.strip()
                if line.removeprefix("xvfb-run -a ").startswith(prefix + " ") or line == prefix:
                    out.append((f"{b.page}:{i}", line))
    return out


COMMANDS = [(where, line) for where, line in _lines("gcmh") if "tcp://" not in line]
APP_LINES = _lines("gcmh-app")


def _needs(code: str) -> list[str]:
    """Optional packages a block uses (it may be skipped only when they are missing)."""
    wanted = []
    if "save_vtu" in code or "pyvista" in code or "--vtu" in code:
        wanted.append("pyvista")
    if "scheduler=" in code or "--scheduler" in code:
        wanted.append("distributed")
    return [m for m in wanted if importlib.util.find_spec(m) is None]


# The child: each job in its own folder; a script as `python script.py` runs it (a fresh module
# __main__ with the script's __file__, argv and sys.path[0] as python sets them: a Dask cluster's
# spawned workers then import the script, as they would), a command line through gcmh's main().
# sys.stdout and sys.stderr are real files (the CLI writes .npz bytes to sys.stdout.buffer).
CHILD = r"""
import builtins, importlib.machinery, json, os, sys, traceback, types
jobs = json.load(open(sys.argv[1]))
child_main = sys.modules["__main__"]
statuses = []
for job in jobs:
    folder = job["folder"]
    os.chdir(folder)
    saved = sys.stdout, sys.stderr, list(sys.argv), list(sys.path)
    sys.stdout, sys.stderr = open(folder + ".out", "w"), open(folder + ".err", "w")
    status = 0
    try:
        if job["script"] is not None:
            path = os.path.join(folder, "script.py")
            module = types.ModuleType("__main__")
            module.__dict__.update(__file__=path, __cached__=None, __builtins__=builtins,
                                 __loader__=importlib.machinery.SourceFileLoader("__main__", path))
            if "__annotations__" in vars(child_main):   # (as this Python gives a __main__ one, or not)
                module.__annotations__ = {}
            sys.argv, sys.path[0], sys.modules["__main__"] = ["script.py"], folder, module
            exec(compile(open(path).read(), path, "exec"), module.__dict__)
        else:
            from gcmh_core.cli import main
            status = main(job["argv"]) or 0
    except SystemExit as stop:
        status = 0 if stop.code in (None, 0) else 1
        if status:
            print(f"SystemExit({stop.code!r})", file=sys.stderr)
    except BaseException:
        traceback.print_exc()
        status = 1
    finally:
        sys.stdout.close(), sys.stderr.close()
        sys.stdout, sys.stderr, sys.argv, sys.path = saved
        sys.modules["__main__"] = child_main
    statuses.append(status)
print(json.dumps(statuses))
"""


def _run_jobs(jobs: dict[str, dict], root: Path) -> dict[str, dict]:
    """Run ``jobs`` {name: dict(script=code or None, argv=[...])} in one child, each in the empty
    folder root/name; return {name: dict(status, stdout, stderr, folder)}."""
    spec = []
    for name, job in jobs.items():
        folder = root / name
        folder.mkdir()
        if job["script"] is not None:
            (folder / "script.py").write_text(job["script"], encoding="utf-8")
        spec.append(dict(job, folder=str(folder)))
    (root / "jobs.json").write_text(json.dumps(spec))
    proc = subprocess.run([sys.executable, "-c", CHILD, str(root / "jobs.json")], cwd=root, capture_output=True,
                          text=True, timeout=1200)
    assert proc.returncode == 0, proc.stderr
    statuses = json.loads(proc.stdout.strip().splitlines()[-1])
    return {name: dict(status=s, stdout=(root / f"{name}.out").read_text(), stderr=(root / f"{name}.err").read_text(),
                       folder=root / name) for s, name in zip(statuses, jobs)}


PROBE = """\
import json, os, sys
print(json.dumps(dict(name=__name__, argv=sys.argv, file=__file__, path0=sys.path[0], cwd=os.getcwd(),
                      main_file=sys.modules["__main__"].__file__, spec=repr(__spec__), package=__package__,
                      names=sorted(globals()), listing=sorted(os.listdir()))))
"""


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict:
    """{"page:line": the run of that block or line}; a text on two pages (the same script, or the
    same command with another comment) runs once."""
    jobs: dict[str, dict] = {"probe": dict(script=PROBE, argv=None)}
    keys: dict[str, str] = {}   # what runs -> its job's name
    where_job = {}
    for b in SCRIPTS:
        if not _needs(b.code):
            name = keys.setdefault(b.code, f"script-{len(keys)}")
            jobs[name] = dict(script=b.code, argv=None)
            where_job[f"{b.page}:{b.line}"] = name
    for where, line in COMMANDS:
        argv = shlex.split(line, comments=True)   # as bash splits it: quotes, and the comment dropped
        assert argv[0] == "gcmh", line
        if not _needs(line):
            name = keys.setdefault(json.dumps(argv), f"command-{len(keys)}")
            jobs[name] = dict(script=None, argv=argv[1:])
            where_job[where] = name
    results = _run_jobs(jobs, tmp_path_factory.mktemp("docs"))
    return dict(results, **{where: results[name] for where, name in where_job.items()})


def test_the_docs_have_scripts_and_commands():
    assert len(SCRIPTS) >= 8 and len(COMMANDS) >= 12 and len(APP_LINES) >= 8
    assert any(line.split("#")[0].split() == ["gcmh", "examples"] for _, line in COMMANDS)
    assert sum(len(_links(page)) for page in PAGES) >= 40
    readme = [b for b in BLOCKS if b.page == "README.md"]
    assert any(b.info == "python" for b in readme) and any(b.info == "bash" for b in readme)


def test_every_fence_says_what_it_is():
    """A block marked ```py or ```sh would silently not run: only the known info strings are allowed,
    and a block that is not run says why."""
    for b in BLOCKS:
        assert b.info.split(":")[0].strip() in INFOS, f"{b.page}:{b.line}: ```{b.info}"
        if b.info.startswith("python no-run"):
            reason = b.info.partition(":")[2].strip()
            assert len(reason) > 10, f"{b.page}:{b.line}: say why the block does not run (```python no-run: why)"


def test_a_script_runs_as_python_runs_it(runs, tmp_path):
    """The child runs a block as `python script.py` in its folder would (so a missing main guard fails here too)."""
    (tmp_path / "script.py").write_text(PROBE)
    real = json.loads(subprocess.run([sys.executable, "script.py"], cwd=tmp_path, capture_output=True, text=True,
                                     check=True).stdout)
    here = json.loads(runs["probe"]["stdout"])
    for got, folder in ((real, tmp_path), (here, runs["probe"]["folder"])):
        for key in ("file", "main_file", "path0", "cwd"):
            got[key] = os.path.relpath(got[key], folder)
    assert here == real
    assert real["name"] == "__main__" and real["listing"] == ["script.py"]


@pytest.mark.parametrize("block", SCRIPTS, ids=[f"{b.page}:{b.line}" for b in SCRIPTS])
def test_python_block_runs_as_a_script(block, runs):
    missing = _needs(block.code)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    run = runs[f"{block.page}:{block.line}"]
    assert run["status"] == 0, f"{block.page}:{block.line}\n{block.code}\n--- stderr:\n{run['stderr']}"
    if "print(" in block.code:
        assert run["stdout"].strip()


@pytest.mark.parametrize(("where", "line"), COMMANDS, ids=[where for where, _ in COMMANDS])
def test_gcmh_line_runs(where, line, runs):
    missing = _needs(line)
    if missing:
        pytest.skip(f"needs {', '.join(missing)}")
    run = runs[where]
    assert run["status"] == 0, f"{line}\n--- stderr:\n{run['stderr']}"
    assert run["stdout"].strip()
    for name in re.findall(r"(?:-o|--vtu) (\S+)", line):  # the files it says it writes
        assert (run["folder"] / name).stat().st_size > 0, name


def test_the_installed_gcmh_runs_through_bash(tmp_path):
    """The console script beside this interpreter, on PATH, as a reader types the docs' lines."""
    line = next(line for _, line in COMMANDS if line.split("#")[0].split() == ["gcmh", "examples"])
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    proc = subprocess.run(["bash", "-c", line], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, f"{line}\n--- stderr:\n{proc.stderr}"
    assert "klein-bottle" in proc.stdout


def test_gcmh_app_lines_use_options_it_has():
    """The app's lines need a display to run; their options and examples are checked against the app itself."""
    from gcmh_core.examples import example_names

    proc = subprocess.run([str(BIN / "gcmh-app"), "--help"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    options = set(re.findall(r"(--[a-z][a-z0-9-]*)", proc.stdout))
    assert {"--example", "--screenshot", "--animate"} <= options
    examples = set(example_names())
    for where, line in APP_LINES:
        argv = shlex.split(line.removeprefix("xvfb-run -a "), comments=True)
        for i, arg in enumerate(argv[1:], start=1):
            if arg.startswith("--"):
                assert arg.split("=")[0] in options, f"{where}: {arg} is not an option of gcmh-app"
            if argv[i - 1] == "--example":
                assert arg in examples, f"{where}: no example {arg!r}"


# --------------------------------------------------------------------------- links


def _prose(text: str) -> str:
    """The page without its code blocks and code spans (where brackets and # mean something else)."""
    text = FENCE.sub("", text)
    return re.sub(r"(`+)[\s\S]+?\1", "", text)


def _anchor(heading: str) -> str:
    """GitHub's id for a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"[`*_]|<[^>]+>", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def _anchors(page: Path) -> set[str]:
    return {_anchor(h) for h in re.findall(r"^#{1,6} (.+)$", _prose(page.read_text(encoding="utf-8")), flags=re.M)}


def _links(page: Path) -> list[str]:
    text = _prose(page.read_text(encoding="utf-8"))
    return re.findall(r"\]\(([^)\s]+)\)", text) + re.findall(r"<(?:img|a)\b[^>]*\b(?:src|href)=\"([^\"]+)\"", text)


@pytest.mark.parametrize("page", PAGES, ids=[str(p.relative_to(ROOT)) for p in PAGES])
def test_every_link_leads_to_a_file(page):
    for link in _links(page):
        if re.match(r"[a-z]+:", link):   # https://, mailto:
            continue
        path, _, anchor = link.partition("#")
        target = (page.parent / path).resolve() if path else page
        assert target.exists(), f"{page.relative_to(ROOT)}: {link} leads nowhere"
        assert ROOT in target.parents or target == ROOT, f"{page.relative_to(ROOT)}: {link} leaves the repository"
        if anchor and target.suffix == ".md":
            assert anchor in _anchors(target), f"{page.relative_to(ROOT)}: {link}: no heading #{anchor}"


def test_the_index_lists_every_page():
    """A page no other page leads to is never read: docs/index.md names each, and the README the index."""
    index = ROOT / "docs" / "index.md"
    listed = {(index.parent / link.partition("#")[0]).resolve() for link in _links(index)}
    for page in PAGES[1:]:
        assert page == index or page in listed, f"docs/index.md does not list {page.name}"
    assert "docs/index.md" in _links(ROOT / "README.md")


def test_the_readme_fits_a_screen_or_two():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 200
    first_screen = "\n".join(text.splitlines()[:12])   # the title, what it is, and the picture
    assert first_screen.startswith("# GCMH Studio")
    assert re.search(r"<img src=\"assets/|!\[[^]]*\]\(assets/", first_screen)
    # CI runs the README's test command (.ci/run)
    assert any(line.split("#")[0].strip() == "bash tests/run.sh"
               for b in BLOCKS if b.page == "README.md" and b.info == "bash" for line in b.code.splitlines())
    assert "bash tests/run.sh" in (ROOT / ".ci" / "run").read_text()


def test_the_examples_page_is_generated_from_the_example_files(monkeypatch):
    monkeypatch.delenv("GCMH_EXAMPLES_DIR", raising=False)
    spec = importlib.util.spec_from_file_location("make_examples", ROOT / "docs" / "make_examples.py")
    make_examples = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make_examples)
    assert (ROOT / "docs" / "examples.md").read_text(encoding="utf-8") == make_examples.markdown(), (
        f"docs/examples.md is not what the example files give: run `{make_examples.COMMAND}`")
