"""Every ```python block of README.md and docs/**/*.md runs as written.

A page's blocks run in order in one namespace, in a fresh Python process started in the
repository root with matplotlib's Agg backend (no display), as a reader would paste them. Blocks
that are not meant to run (shell sessions, listings, pseudo-code) use another fence language
(```bash, ```console, ```text). A file an example writes inside the repository must be in a
folder git ignores (out/): the child process reports every file opened for writing or renamed
(an audit hook), and the test asks ``git check-ignore`` about those inside the repository.

One test per page (``pytest tests/test_doc_examples.py -k clearance`` runs one page);
``python tests/test_doc_examples.py docs/clearance.md`` prints what a page's blocks do.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: an opening ```python fence (possibly indented, in a list item) up to its closing fence
FENCE = re.compile(r"^(?P<indent>[ \t]*)```python[ \t]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$",
                   re.S | re.M)  # fmt: skip
#: seconds a page may take (the slowest takes a few seconds; this only stops a hung page)
TIMEOUT = 300

#: The child process: runs the blocks given as JSON on stdin in one namespace and writes what it
#: wrote to disk (as JSON, on the last line of stdout) after the marker.
CHILD = r"""
import json, os, sys, traceback
import matplotlib
matplotlib.use("Agg")
written = set()
def audit(event, args):
    if event == "open" and args[0] is not None and not isinstance(args[0], int):
        mode, flags = args[1], args[2]
        if (mode and any(c in mode for c in "wax+")) or (
                not mode and flags & (os.O_WRONLY | os.O_RDWR | os.O_CREAT)):
            written.add(os.path.abspath(os.fsdecode(args[0])))
    elif event in ("os.rename", "os.replace"):
        written.add(os.path.abspath(os.fsdecode(args[1])))
    elif event == "os.mkdir":
        written.add(os.path.abspath(os.fsdecode(args[0])))
sys.addaudithook(audit)
page, blocks = json.load(sys.stdin)
namespace = {"__name__": "__main__"}
status = 0
for index, (line, source) in enumerate(blocks, 1):
    try:
        code = compile(source, f"{page}, block {index} (line {line})", "exec")
        exec(code, namespace)
    except BaseException:
        traceback.print_exc()
        print(f"{page}: block {index} (line {line}) failed", file=sys.stderr)
        status = 1
        break
sys.stdout.flush()
print("\n@@written@@" + json.dumps(sorted(written)))
sys.exit(status)
"""


def python_blocks(text: str) -> list[tuple[int, str]]:
    """The ```python blocks of a Markdown text: (line of the opening fence, source dedented)."""
    blocks = []
    for match in FENCE.finditer(text):
        line = text.count("\n", 0, match.start()) + 1
        indent = len(match["indent"])
        body = "".join(row[indent:] if not row[:indent].strip() else row.lstrip()
                       for row in match["body"].splitlines(keepends=True))  # fmt: skip
        blocks.append((line, body))
    return blocks


def pages() -> list[str]:
    """README.md and every page under docs/ with at least one ```python block (relative)."""
    found = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    return [
        path.relative_to(ROOT).as_posix()
        for path in found
        if python_blocks(path.read_text(encoding="utf-8"))
    ]


def run_page(page: str) -> subprocess.CompletedProcess:
    """Run ``page``'s blocks in a fresh process (cwd = the repository root, Agg backend)."""
    return run_blocks(page, python_blocks((ROOT / page).read_text(encoding="utf-8")))


def run_blocks(page: str, blocks: list[tuple[int, str]]) -> subprocess.CompletedProcess:
    """Run ``blocks`` (line, source) in order in one namespace of a fresh process."""
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run(
        [sys.executable, "-c", CHILD],
        input=json.dumps([page, blocks]),
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=TIMEOUT,
    )


def written_files(done: subprocess.CompletedProcess) -> list[str]:
    """The absolute paths the child opened for writing, renamed to or made as folders."""
    _, marker, tail = done.stdout.rpartition("@@written@@")
    assert marker, "the page's process ended before reporting:\n" + done.stdout + done.stderr
    return json.loads(tail)


def not_ignored(paths: list[str]) -> list[str]:
    """Those of ``paths`` inside the repository that git does not ignore."""
    inside = [p for p in paths if Path(p).is_relative_to(ROOT)]
    if not inside:
        return []
    done = subprocess.run(
        ["git", "check-ignore", "--stdin", "-z"],
        input="\0".join(inside),
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert done.returncode in (0, 1), done.stderr  # 1: none ignored
    ignored = set(filter(None, done.stdout.split("\0")))
    return [p for p in inside if p not in ignored]


PAGES = pages()


def test_the_pages_with_examples_are_found():
    """The README's API example and the pages that teach the API are all run."""
    for page in ("README.md", "docs/clearance.md", "docs/exports.md", "docs/trees.md"):
        assert page in PAGES, page
    assert len(python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))) >= 1


def test_no_python_hides_under_another_fence_language():
    """Python is fenced ```python (and then run); pages that are not meant to run use bash,
    console or text, never a Python-looking name this test would not run."""
    hidden = {"py", "py3", "python3", "pycon", "ipython", "pyi"}
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        languages = re.findall(r"^[ \t]*```[ \t]*([\w+-]+)", path.read_text(encoding="utf-8"), re.M)
        assert not hidden & {language.lower() for language in languages}, path


def test_python_blocks_are_extracted_as_written():
    text = "a\n```python\nx = 1\n```\n\n1. item\n\n   ```python\n   y = x\n   ```\n"
    text += "```bash\nls\n```\n"
    assert python_blocks(text) == [(2, "x = 1\n"), (8, "y = x\n")]


def test_the_runner_reports_failures_and_written_files(tmp_path):
    target = tmp_path / "made.txt"
    blocks = [(3, f"x = {str(target)!r}\n"), (9, "open(x, 'w').write('1')\n"),
              (12, "import matplotlib\nbackend = matplotlib.get_backend()\n"),
              (20, "assert backend.lower() == 'agg', backend\nundefined_name\n"),
              (30, "open(x + '.never', 'w')\n")]  # fmt: skip
    done = run_blocks("page.md", blocks)
    assert done.returncode == 1
    assert "page.md, block 4 (line 20)" in done.stderr and "NameError" in done.stderr
    assert written_files(done) == [str(target)]  # block 5 did not run
    assert run_blocks("page.md", blocks[:3]).returncode == 0


def test_only_files_git_ignores_may_be_written_in_the_repository(tmp_path):
    inside = [str(ROOT / "out" / "a.png"), str(ROOT / "a.png"), str(ROOT / "README.md")]
    assert not_ignored([*inside, str(tmp_path / "b.png")]) == inside[1:]


@pytest.fixture(scope="module")
def runs(request):
    """The pages of the selected tests, run side by side (one process per core): ``--dist
    loadfile`` gives this whole file to one worker."""
    selected = [item.callspec.params["page"] for item in request.session.items
                if getattr(item, "module", None) is request.module
                and hasattr(item, "callspec")]  # fmt: skip
    pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
    futures = {page: pool.submit(run_page, page) for page in dict.fromkeys(selected)}
    yield futures
    pool.shutdown(cancel_futures=True)


@pytest.mark.parametrize("page", PAGES)
def test_every_python_block_runs(page, runs):
    done = runs[page].result() if page in runs else run_page(page)
    assert done.returncode == 0, f"{page}:\n{done.stderr[-6000:]}"
    stray = not_ignored(written_files(done))
    assert not stray, f"{page} writes files git does not ignore: {stray}"


if __name__ == "__main__":
    for name in sys.argv[1:] or PAGES:
        result = run_page(name)
        print(f"== {name}: exit {result.returncode}")
        print(result.stdout.rpartition("@@written@@")[0][-3000:])
        print(result.stderr[-4000:])
