"""No module imports another library's private module or name, except the one wrapper that
names them (rigedit/model/fast_paths.py: checked at import, with a public fallback)."""
import ast

from testpaths import REPO

#: The one place allowed to name another library's private API (issue 18).
WRAPPER = "rigedit/model/fast_paths.py"


def _private(dotted):
    return any(part.startswith("_") and not part.startswith("__") for part in dotted.split("."))


def private_imports(tree):
    """(line, what) of each import of a private module or name of another package."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names
                      if not a.name.startswith("rigedit") and _private(a.name)]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module \
                and not node.module.startswith("rigedit"):
            names = [f"{node.module}.{a.name}" for a in node.names]
            found += [(node.lineno, n) for n in names if _private(n)]
    return found


def test_only_the_wrapper_imports_private_apis_of_other_libraries():
    offenders = []
    for path in sorted((REPO / "rigedit").rglob("*.py")):
        rel = path.relative_to(REPO).as_posix()
        if rel == WRAPPER:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=rel)
        offenders += [f"{rel}:{line}: {what}" for line, what in private_imports(tree)]
    assert offenders == [], "private APIs outside " + WRAPPER + ":\n" + "\n".join(offenders)


def test_the_wrapper_is_seen_by_the_check():
    tree = ast.parse((REPO / WRAPPER).read_text(encoding="utf-8"))
    assert [what for _, what in private_imports(tree)] == [
        "scipy.sparse._sparsetools.csr_matvecs"]
