"""Where the course is, and the error a user can fix.

Every module of the package but grade imports this one; it imports only grade.
"""
import os
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
