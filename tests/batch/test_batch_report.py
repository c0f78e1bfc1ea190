"""OUTDIR/report.html in a real browser: headless Chromium loads the page, runs its script,
and the test reads the DOM it dumps (rows, thumbnails, filters and sorting from the URL's
fragment)."""
import re
import shutil
import subprocess

import pytest

from batch_helpers import run_in_process
from rigedit.batch.report import write_report

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs chromium (python3 dev.py "
                                                         "installs it on Debian)")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """Two retargets with thumbnails, one of them made unsure, and a broken input."""
    out, _, entries = run_in_process(tmp_path_factory.mktemp("report"), thumbnails=True)
    assert entries[2]["input"].endswith("broken.bvh")
    entries[1]["unsure"] = ["unmapped: left arm"]   # as a partial map gives
    return write_report(out, "retarget", entries), entries


def _dom(page, fragment=""):
    done = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu",
                           "--dump-dom", page.as_uri() + fragment],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def _rows(dom):
    """(task input name, hidden) per body row, in the order shown."""
    body = dom.split("<tbody>", 1)[1]
    rows = re.findall(r"<tr ([^>]*)>.*?<td class=\"path\"[^>]*>([^<]*)</td>", body, re.S)
    return [(name, re.search(r"(^|\s)hidden(=\"\")?(\s|$)", attrs) is not None)
            for attrs, name in rows]


def test_one_row_per_task_with_its_thumbnail(report):
    page, entries = report
    dom = _dom(page)
    rows = _rows(dom)
    assert len(rows) == 3 and not any(hidden for _, hidden in rows)
    # those that need a look first (failed, unsure), then in the manifest's order
    names = [e["input"].rsplit("/", 1)[1] for e in entries]
    assert [n for n, _ in rows] == [names[1], names[2], names[0]]
    thumbs = re.findall(r'<img class="thumb" src="([^"]+)"', dom)
    assert len(thumbs) == 2   # the broken input has none
    for src in thumbs:
        assert (page.parent / src).stat().st_size > 1000
    assert "3 of 3 shown" in dom
    assert "http://" not in dom and "https://" not in dom   # nothing from the network


def test_the_status_filter_hides_the_rows_that_succeeded(report):
    page, _ = report
    rows = _rows(_dom(page, "#status=failed"))
    assert [name for name, hidden in rows if not hidden] == ["broken.bvh"]
    assert sum(hidden for _, hidden in rows) == 2


def test_needs_a_look_shows_failed_and_unsure_first(report):
    page, entries = report
    rows = _rows(_dom(page, "#look=1"))
    shown = [name for name, hidden in rows if not hidden]
    assert sorted(shown) == sorted(["broken.bvh", entries[1]["input"].rsplit("/", 1)[1]])
    assert [hidden for _, hidden in rows] == [False, False, True]   # shown rows first


def test_sorting_by_a_column_from_the_fragment(report):
    page, entries = report
    rows = _rows(_dom(page, "#sort=time-s&desc=1"))
    by_time = sorted(entries, key=lambda e: -e["seconds"])
    assert [n for n, _ in rows] == [e["input"].rsplit("/", 1)[1] for e in by_time]
