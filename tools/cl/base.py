"""Where the course is, and the error a user can fix.

Every module of the package but grade imports this one; it imports only grade.
"""
import os
import shutil
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

from . import grade

ROOT = Path(__file__).resolve().parent.parent.parent
BUILD = ROOT / os.environ.get("CL_BUILD_DIR", "build")
BIN = BUILD / "bin"
# The build is configured once, in Release (build.configure); a multi-config
# generator (Visual Studio, Xcode: where no Ninja is installed) builds it as
# --config Release (build.build_command) into bin/Release/.
CONFIG = "Release"
EXE = ".exe" if os.name == "nt" else ""


class CourseError(Exception):
    """A problem the user can fix: its details (a program's stderr), one line, exit `code`."""

    def __init__(self, message, code=1, details=()):
        super().__init__(message)
        self.code = code
        self.details = list(details)


def program(name, bin_dir=None):
    """The executable NAME of a build (build/bin by default) as the build wrote
    it: NAME.exe on Windows, bin/Release/NAME under a multi-config generator.
    The single-config path when neither exists (a message names it)."""
    bin_dir = Path(bin_dir or BIN)
    path = bin_dir / (name + EXE)
    configured = bin_dir / CONFIG / (name + EXE)
    return configured if not path.exists() and configured.exists() else path


def become(path, argv):
    """Run the program PATH with ARGV (argv[0] its name) in this command's
    place; its exit code is the command's. On POSIX by os.execv: the program
    itself then gets the terminal's Ctrl-C and a SIGTERM (the live mode stops
    cleanly on either, and a signal's exit status stays the program's). On
    Windows execv starts a new process and ends this one, so that the shell
    would see the command end at once: a child is waited for instead (the
    console sends Ctrl-C to both; the program's exit code is returned)."""
    sys.stdout.flush()
    sys.stderr.flush()
    if os.name != "nt":
        os.execv(path, argv)
    child = subprocess.Popen([str(path), *argv[1:]])
    while True:
        try:
            return child.wait()
        except KeyboardInterrupt:
            continue


def show(path):
    """A path as the user should read it: relative to the course root when inside it."""
    return grade.relative(path, ROOT)


def under_root(path):
    return ROOT / path  # an absolute `path` stays as it is


@contextmanager
def check_tree():
    """A fresh folder for a check's temporary course tree, removed afterwards;
    always the same path, BUILD/check-tree. ccache keys a compile on its
    source's path, so the student loop's release and the autograder's bundle,
    built there one after the other at the same relative places, share the
    objects of the files they have in common (common/, labs 01 and 02)
    instead of compiling them twice."""
    path = BUILD / "check-tree"
    shutil.rmtree(path, ignore_errors=True)
    path.mkdir(parents=True)
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)
