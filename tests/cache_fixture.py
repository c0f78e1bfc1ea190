"""The user's cache folder (recovery entries, the log) moved into the test's tmp_path."""
import pytest


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """``$XDG_CACHE_HOME`` in tmp_path; returns the rigedit cache folder inside it."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "rigedit"
