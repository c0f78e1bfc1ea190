"""``OUTDIR/report.html``: one row per task, for a person in a browser.

Self-contained: the CSS and the script are inline, nothing is fetched from the network; the
thumbnails are files in OUTDIR referenced relatively (the page works from a copy of OUTDIR).
The rows are written as HTML (the page reads without its script); the script puts the rows
that need a look (failed, or a result the job is not sure of) first, sorts by any column
(click its heading) and filters by status and by "needs a look". The filter and the sort
live in the address's fragment (``report.html#status=failed&look=1&sort=time&desc=1``; a
part that is not valid percent-encoding is left out, not fatal) so a link keeps
them and a test can load the page in that state.
"""
from __future__ import annotations

import datetime
import html
import math
from pathlib import Path
from urllib.parse import quote

from ..io.atomic import atomic_write
from .inputs import name_bytes, shown
from .manifest import rigedit_version

__all__ = ["write_report", "needs_look"]

_STYLE = """
body{font:14px/1.4 system-ui,sans-serif;margin:16px;color:#222;background:#fafafa}
h1{font-size:20px;margin:0 0 4px}.sum{margin:0 0 12px;color:#555}
.bar{margin:8px 0 12px;display:flex;gap:16px;align-items:center}
table{border-collapse:collapse;background:#fff;width:100%}
th,td{border-bottom:1px solid #ddd;padding:4px 8px;text-align:left;vertical-align:top}
th{background:#eee;cursor:pointer;position:sticky;top:0;font-size:13px;max-width:120px}
th.asc::after{content:" \\25B2"}th.desc::after{content:" \\25BC"}
td.num{text-align:right;font-variant-numeric:tabular-nums}
tr.failed{background:#fdecea}tr.look:not(.failed){background:#fff8e1}
.st{font-weight:600}.failed .st{color:#b71c1c}.ok .st{color:#1b5e20}
.why{color:#b71c1c;font-size:12px;max-width:380px}.warn{color:#8d6e00;font-size:12px}
img.thumb{height:96px;background:#ddd;border:1px solid #ccc}
.path{font-family:ui-monospace,monospace;font-size:12px;overflow-wrap:anywhere;min-width:150px;max-width:240px}
.outs{font-size:11px;max-width:200px;overflow-wrap:anywhere}
"""

_SCRIPT = """
(function(){
const table=document.getElementById('tasks'),body=table.tBodies[0];
const heads=[...table.tHead.rows[0].cells],st=document.getElementById('status'),
lk=document.getElementById('look'),shown=document.getElementById('shown');
function dec(x){try{return decodeURIComponent(x)}catch(e){return null}}
function state(){const s={};location.hash.slice(1).split('&').forEach(p=>{
 const [k,v]=p.split('='),dk=dec(k||''),dv=dec(v||'');if(dk&&dv!==null)s[dk]=dv});return s}
function key(row,i){const c=row.cells[i],v=c.dataset.v!==undefined?c.dataset.v:c.textContent;
 const n=parseFloat(v);return v!==''&&!isNaN(n)&&isFinite(v)?n:v.toLowerCase()}
function apply(){const s=state(),status=s.status||'all',look=s.look==='1';
 st.value=status;lk.checked=look;
 const col=heads.findIndex(h=>h.dataset.k===s.sort),desc=s.desc==='1';
 const rows=[...body.rows];
 rows.sort((a,b)=>{if(look||col<0){const d=b.dataset.look-a.dataset.look;if(d)return d}
  if(col<0)return a.dataset.i-b.dataset.i;
  const x=key(a,col),y=key(b,col);
  if(typeof x!==typeof y)return (typeof x==='number'?-1:1);
  return (x<y?-1:x>y?1:0)*(desc?-1:1)});
 let n=0;rows.forEach(r=>{const hide=(status!=='all'&&r.dataset.status!==status)||
  (look&&r.dataset.look!=='1');r.hidden=hide;n+=!hide;body.appendChild(r)});
 heads.forEach((h,i)=>h.className=i===col?(desc?'desc':'asc'):'');
 shown.textContent=n+' of '+rows.length+' shown'}
function set(ch){const s=Object.assign(state(),ch);location.hash=Object.keys(s)
 .filter(k=>s[k]!==''&&s[k]!==undefined).map(k=>k+'='+encodeURIComponent(s[k])).join('&')}
heads.forEach(h=>h.onclick=()=>{const s=state();
 set({sort:h.dataset.k,desc:s.sort===h.dataset.k&&s.desc!=='1'?'1':''})});
st.onchange=()=>set({status:st.value==='all'?'':st.value});
lk.onchange=()=>set({look:lk.checked?'1':''});
window.addEventListener('hashchange',apply);apply()})();
"""


def needs_look(entry):
    """A task a person should look at: it failed, or its job is not sure of the result."""
    return entry.get("status") != "ok" or bool(entry.get("unsure"))


def _text(value):
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "-" if not math.isfinite(value) else f"{value:g}"
    if isinstance(value, (list, tuple)):
        return "; ".join(_text(v) for v in value) or "-"
    return "-" if value is None else str(value)


def _cell(value, sort=None):
    num = isinstance(value, (int, float)) and not isinstance(value, bool)
    if sort is None and isinstance(value, (list, tuple)):
        sort = len(value)
    data = "" if sort is None else f' data-v="{html.escape(str(sort))}"'
    return f'<td{data}{" class=num" if num else ""}>{html.escape(_text(value))}</td>'


def _href(rel):
    """A path relative to OUTDIR as a relative URL: percent-encoded, so that a name holding
    ``#``, ``%``, ``?`` or ``:`` (``a:b.glb`` read as a scheme) still reaches its file."""
    return html.escape(quote(name_bytes(Path(rel).as_posix())))


def _media(entry):
    thumb = entry.get("thumbnail")
    if not thumb:
        return '<td data-v="0">-</td>'
    src = _href(thumb)
    return (f'<td data-v="1"><a href="{src}"><img class="thumb" src="{src}" loading="lazy" '
            f'alt="preview of {html.escape(entry["task"])}"></a></td>')


def _row(i, entry, quality_keys):
    look = needs_look(entry)
    status = entry.get("status", "failed")
    cls = f"{status}{' look' if look else ''}"
    notes = [html.escape(x) for x in ([entry["error"]] if entry.get("error") else [])
             + [f"NOT SURE: {u}" for u in entry.get("unsure") or []]]
    warns = entry.get("warnings") or []
    outs = " ".join(f'<a href="{_href(o)}">{html.escape(o)}</a>'
                    for o in entry.get("outputs") or []) if status == "ok" else "-"
    cells = [f'<td class="st">{html.escape(status)}</td>', _media(entry),
             f'<td class="path" title="{html.escape(entry.get("input") or "")}">'
             f'{html.escape(Path(entry.get("input") or "-").name)}</td>',
             _cell(Path(entry["target"]).stem if entry.get("target") else None),
             _cell(entry.get("seconds"))]
    q = entry.get("quality") or {}
    cells += [_cell(q.get(k)) for k in quality_keys]
    cells.append(f'<td data-v="{len(notes)}"><div class="why">{"<br>".join(notes)}</div>'
                 + (f'<div class="warn" title="{html.escape(chr(10).join(warns))}">'
                    f'{len(warns)} warning{"s" * (len(warns) != 1)}</div>' if warns else "")
                 + "</td>")
    cells.append(f'<td class="outs">{outs}</td>')
    return (f'<tr class="{cls}" data-i="{i}" data-status="{html.escape(status)}" '
            f'data-look="{int(look)}">' + "".join(cells) + "</tr>")


def write_report(outdir, job, entries, tasks=None):
    """Write ``OUTDIR/report.html`` (atomically) for ``entries``; returns its path.

    Parameters
    ----------
    outdir : Path
    job : str
    entries : list[dict]
        Manifest entries, one row each (in this order until sorted).
    tasks : int, optional
        Tasks planned (rows missing were not run yet: an interrupted batch).
    """
    keys = []
    for e in entries:
        keys += [k for k in (e.get("quality") or {}) if k not in keys]
    failed = sum(e.get("status") != "ok" for e in entries)
    look = sum(needs_look(e) for e in entries)
    heads = (["status", "preview", "input", "target", "time (s)"] + keys
             + ["errors, NOT SURE", "outputs"])
    head = "".join(f'<th data-k="{html.escape(_slug(h))}">{html.escape(h)}</th>' for h in heads)
    missing = (tasks or len(entries)) - len(entries)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    summary = (f"{len(entries)} tasks: {len(entries) - failed} ok, {failed} failed, {look} "
               f"need a look" + (f"; {missing} not run (the batch was stopped)" if missing else "")
               + f". rigedit {rigedit_version()}, {now}.")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>rigedit batch {html.escape(job)}</title>
<style>{_STYLE}</style></head><body>
<h1>rigedit batch: {html.escape(job)}</h1><p class="sum" id="summary">{html.escape(summary)}</p>
<div class="bar"><label>status <select id="status"><option value="all">all</option>
<option value="ok">ok</option><option value="failed">failed</option></select></label>
<label><input type="checkbox" id="look"> needs a look (failed or unsure), first</label>
<span id="shown"></span></div>
<table id="tasks"><thead><tr>{head}</tr></thead><tbody>
{chr(10).join(_row(i, e, keys) for i, e in enumerate(entries))}
</tbody></table><script>{_SCRIPT}</script></body></html>
"""
    path = Path(outdir) / "report.html"
    with atomic_write(path) as fh:
        fh.write(shown(page))   # a name that is no UTF-8: its odd bytes as U+FFFD
    return path


def _slug(text):
    return "-".join("".join(c if c.isalnum() else " " for c in text.lower()).split())
