"""The error types that bad input and failed writes raise: a ``ValueError`` naming the file
and the problem, in one line."""
from __future__ import annotations

import re

__all__ = ["RigFileError", "RigWriteError"]


class RigFileError(ValueError):
    """A file could not be read or written.

    Parameters
    ----------
    path : str or os.PathLike
    problem : str
        What is wrong, as "expected ..., got ...". Line breaks (a library's multi-line
        message quoted in it) are folded into one space each: the message is one line.
    """

    def __init__(self, path, problem):
        self.path = str(path)
        self.problem = re.sub(r"\s*[\r\n]+\s*", " ", str(problem))
        super().__init__(f"{self.path}: {self.problem}")

    def __reduce__(self):
        # picklable with its two arguments (an FBX read in a child process sends its error
        # back: rigedit.io.fbx_isolated)
        return type(self), (self.path, self.problem)


class RigWriteError(RigFileError, OSError):
    """A file or rig folder could not be written (disk full, permission denied, a read-only
    file system): ``path`` is the one the user asked for, never a hidden temporary, and the
    writer has left nothing behind that was not there before.

    Also an ``OSError`` (``errno``, ``strerror``, ``filename`` = ``path``), so callers that
    caught the system's error before keep working; its message is the one line of a
    :class:`RigFileError`.

    Parameters
    ----------
    path : str or os.PathLike
    problem : str
    errno : int, optional
    strerror : str, optional
    """

    def __init__(self, path, problem, errno=None, strerror=None):
        super().__init__(path, problem)
        self.errno, self.strerror, self.filename = errno, strerror, self.path

    def __reduce__(self):
        return type(self), (self.path, self.problem, self.errno, self.strerror)

    def __str__(self):
        return f"{self.path}: {self.problem}"
