"""The one error type that bad input raises: a ``ValueError`` naming the file and the problem."""
from __future__ import annotations

__all__ = ["RigFileError"]


class RigFileError(ValueError):
    """A file could not be read or written.

    Parameters
    ----------
    path : str or os.PathLike
    problem : str
        What is wrong, as "expected ..., got ...".
    """

    def __init__(self, path, problem):
        self.path = str(path)
        self.problem = str(problem)
        super().__init__(f"{self.path}: {self.problem}")
