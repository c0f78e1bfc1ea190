"""Where the tests live: the repository, this folder, and the shared test data beside the
repository (``../shared/data``). Tests sit in folders that mirror the packages
(tests/model/, tests/io/, ...), so they find these from here rather than counting parents."""
from pathlib import Path

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parent
DATA = REPO.parent / "shared" / "data"
