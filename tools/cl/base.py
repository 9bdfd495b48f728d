"""Where the course is, and the error a user can fix.

Every module of the package but grade imports this one; it imports only grade.
"""
import os
import shutil
from contextlib import contextmanager
from pathlib import Path

from . import grade

ROOT = Path(__file__).resolve().parent.parent.parent
BUILD = ROOT / os.environ.get("CL_BUILD_DIR", "build")
BIN = BUILD / "bin"


class CourseError(Exception):
    """A problem the user can fix: its details (a program's stderr), one line, exit `code`."""

    def __init__(self, message, code=1, details=()):
        super().__init__(message)
        self.code = code
        self.details = list(details)


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
