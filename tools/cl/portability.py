"""The course's Python on every system, checked in ./course test (checks.py):
every text file and pipe says its encoding, and the requirement check's
messages for macOS, Windows and Debian without root are the one line each
that requirements.EXPECTED says.

Without an encoding, open(), read_text(), write_text() and a subprocess's
text=True use the locale's (cp1252 on Windows): a source or a compiler
message in UTF-8 then raises UnicodeDecodeError instead of being shown.
Python 3.10's `-X warn_default_encoding` warns at each such call as it runs;
this scan finds them in the source, including the paths no check runs (a
crash rerun, a failed build).
"""
import ast
import time

from .base import ROOT, show
from .requirements import message_problems

SCANNED = ("tools/**/*.py", "plots/*.py", ".ci/*.py")
OPENERS = {"open", "fdopen", "TemporaryFile", "NamedTemporaryFile", "SpooledTemporaryFile", "TextIOWrapper"}


def keyword(call, name):
    return next((k.value for k in call.keywords if k.arg == name), None)


def is_true(node):
    return isinstance(node, ast.Constant) and node.value is True


def call_name(call):
    function = call.func
    return function.attr if isinstance(function, ast.Attribute) else getattr(function, "id", "")


def is_foreign_open(call):
    """An `X.open(...)` that is not Python's own (io.open, os.fdopen, a Path's
    open): PIL's Image.open reads bytes."""
    function = call.func
    return (isinstance(function, ast.Attribute) and function.attr == "open"
            and isinstance(function.value, ast.Name) and function.value.id not in ("io", "os", "codecs"))


def default_encoding_calls(tree):
    """(line, what) of every call in `tree` that reads or writes text without
    an encoding: open() and its kin in a text mode, Path.read_text() and
    write_text(), any call with text=True or universal_newlines=True (a
    subprocess's, or the dict of its options)."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or keyword(node, "encoding") is not None:
            continue
        name = call_name(node)
        if is_true(keyword(node, "text")) or is_true(keyword(node, "universal_newlines")):
            found.append((node.lineno, f"{name}(text=True)"))  # a pipe's, or its options': dict(text=True)
        elif any(k.arg is None for k in node.keywords):
            continue  # **options: said where they are made
        elif name in ("read_text", "write_text"):
            found.append((node.lineno, f"{name}()"))
        elif name in OPENERS and name != "TextIOWrapper" and not is_foreign_open(node):
            at = 0 if name.endswith("TemporaryFile") else 1
            mode = keyword(node, "mode") or (node.args[at] if len(node.args) > at else None)
            if mode is None:
                if name.endswith("TemporaryFile"):
                    continue  # their default mode is binary, w+b
                found.append((node.lineno, f"{name}() in text mode"))
            elif not (isinstance(mode, ast.Constant) and "b" in str(mode.value)):
                found.append((node.lineno, f"{name}() in text mode"))
        elif name == "TextIOWrapper":
            found.append((node.lineno, "TextIOWrapper()"))
    return sorted(found)


def encoding_problems(root=ROOT):
    """`file:line: what` for each call without an encoding in SCANNED."""
    problems = []
    files = sorted({path for pattern in SCANNED for path in root.glob(pattern) if "vendor" not in path.parts})
    for path in files:
        source = path.read_text(encoding="utf-8")
        try:
            tree = ast.parse(source, filename=str(path))
        except SyntaxError as error:
            problems.append(f"{show(path)}:{error.lineno}: does not parse ({error.msg})")
            continue
        problems += [f"{show(path)}:{line}: {what} without encoding=" for line, what in default_encoding_calls(tree)]
    return problems, len(files)


def check_portability(checks):
    """The two checks, about a second between them."""
    start = time.monotonic()
    problems, count = encoding_problems()
    checks.record(not problems, f"every text read, write and pipe of tools/ and plots/ says its encoding "
                  f"({count} files, {len(problems)} calls without one)", problems[:20])
    problems = message_problems()
    checks.record(not problems, "./course's requirement messages: macOS, Windows and Debian without root told "
                  f"what is missing and how to install it in one line, exit 2 ({time.monotonic() - start:.1f} s)",
                  problems)
