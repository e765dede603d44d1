"""The wheel carries the command line: the `nprt` command and `python -m nprt` are nprt's own,
and the quick starts of README.md and docs/python.md run exactly as written (extracted from the
files, so they cannot drift)."""

import os
import pathlib
import re
import shutil
import subprocess
import sys

from conftest import REPO

BIN = pathlib.Path(sys.executable).parent


def run(args, cwd, **kw):
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}"}
    return subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, **kw)


def blocks(path, language, after):
    """The fenced `language` blocks of `path` that follow the line containing `after`."""
    text = (REPO / path).read_text(encoding="utf-8")
    text = text[text.index(after):]
    return re.findall(rf"```{language}\n(.*?)```", text, re.S)


def test_the_nprt_command_and_python_m_nprt_are_the_command_line(tmp_path):
    assert shutil.which("nprt", path=str(BIN)), "pip installed no nprt command"
    for cmd in (["nprt"], [sys.executable, "-m", "nprt"]):
        version = run([*cmd, "--version"], tmp_path)
        assert version.returncode == 0 and version.stdout.startswith("nprt "), version
        refused = run([*cmd, "generate", "--scene", "builtin:room"], tmp_path)
        assert refused.returncode == 2 and "--envmaps" in refused.stderr, refused
        bad = run([*cmd, "reference", "missing.xml", "--out", "x.exr"], tmp_path)
        assert bad.returncode == 1 and "missing.xml" in bad.stderr, bad
        assert "Traceback" not in bad.stderr + refused.stderr


def test_the_python_quick_starts_run_as_written(tmp_path):
    # docs/python.md: the shell commands that make a model, then the Python that relights it.
    for command in blocks("docs/python.md", "sh", "## In five lines")[0].splitlines():
        if command.strip() and not command.startswith("#"):
            done = run(command, tmp_path, shell=True, timeout=600)
            assert done.returncode == 0, (command, done.stderr)
    python = blocks("docs/python.md", "python", "## In five lines")[0]
    readme = blocks("README.md", "python", "And from Python")[0]
    for code in (python, readme):
        scope = {}
        cwd = os.getcwd()
        os.chdir(tmp_path)
        try:
            exec(compile(code, "quick start", "exec"), scope)
        finally:
            os.chdir(cwd)
        frame = scope["frame"]
        assert frame.ndim == 3 and frame.shape[2] == 3 and frame.mean() > 0


def test_the_notebook_example_runs_as_written(tmp_path, capsys):
    # docs/python.md: the network on a dataset view's arrays, and the view's transfer vectors.
    code = blocks("docs/python.md", "python", "In a notebook, the network")[0]
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        exec(compile(code, "notebook example", "exec"), {})
    finally:
        os.chdir(cwd)
    printed = capsys.readouterr().out.splitlines()
    assert float(printed[0]) >= 0 and printed[1] == "(32, 32, 4, 3)", printed
    assert printed[2].startswith("(64,)"), printed
