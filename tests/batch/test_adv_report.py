"""Adversarial reports: file names with characters that mean something in HTML or in a URL
(``<``, quotes, ``#``, ``%``, ``?``, ``:``), and fragments a person typed or cut short."""
import html
import re
from html.parser import HTMLParser
from urllib.parse import unquote, urlsplit

import pytest

from rigedit.batch.report import write_report
from test_batch_report import CHROMIUM, _dom

needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason="needs chromium")

NAMES = ["#1 walk", "100% run", "what?", "a:b", "it's \"q\"", "<img src=x onerror=alert(1)>",
         "-dash", "歩く &amp; x"]


def _entries(tmp_path):
    entries = []
    for i, name in enumerate(NAMES):
        out = f"{name}__humanoid.glb"
        (tmp_path / out).write_text("x")
        entries.append({"task": f"retarget-t{i}", "job": "retarget",
                        "input": f"/lib/{name}.bvh", "target": "humanoid",
                        "status": "failed" if i % 3 == 0 else "ok",
                        "error": f"{name}.bvh: expected HIERARCHY" if i % 3 == 0 else None,
                        "outputs": [out], "thumbnail": None, "seconds": 1.0 + i,
                        "quality": {"frames": 10 * i}, "unsure": [], "warnings": [name]})
    return entries


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.hrefs, self.tags = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        if tag == "a":
            self.hrefs.append(dict(attrs)["href"])


def test_output_links_reach_their_files_whatever_their_names(tmp_path):
    # href="#1 walk__humanoid.glb" was a link to this page's fragment, "a:b..." a scheme
    entries = _entries(tmp_path)
    page = write_report(tmp_path, "retarget", entries)
    parser = _Links()
    parser.feed(page.read_text())
    assert parser.tags.count("script") == 1 and parser.tags.count("img") == 0
    oks = [e["outputs"][0] for e in entries if e["status"] == "ok"]
    assert len(parser.hrefs) == len(oks)
    for href, name in zip(parser.hrefs, oks):
        parts = urlsplit(href)
        assert not parts.scheme and not parts.netloc and not parts.fragment and not parts.query
        assert (page.parent / unquote(parts.path)).is_file(), href


@needs_chromium
def test_a_malformed_fragment_still_filters_and_names_stay_text(tmp_path):
    # decodeURIComponent("%E0%A4%A") threw URIError: the script stopped, no filter, no sort
    out = tmp_path / "out #1 100%"
    out.mkdir()
    entries = _entries(out)
    page = write_report(out, "retarget", entries)
    dom = _dom(page, "#status=failed&sort=%E0%A4%A&x=%")
    failed = sum(e["status"] == "failed" for e in entries)
    assert f"{failed} of {len(entries)} shown" in dom
    rows = re.findall(r"<tr ([^>]*)>", dom.split("<tbody>", 1)[1])
    assert sum("hidden" in r for r in rows) == len(entries) - failed
    assert dom.count("<script") == 1 and "<img src=\"x\"" not in dom
    assert "&lt;img src=x onerror=alert(1)&gt;.bvh" in dom
    # a sort by a column still works beside a broken part
    dom = _dom(page, "#sort=frames&desc=1&junk=%ZZ")
    names = [html.unescape(n) for n in
             re.findall(r'<td class="path"[^>]*>([^<]*)</td>', dom.split("<tbody>", 1)[1])]
    assert names == [f"{n}.bvh" for n in reversed(NAMES)]
