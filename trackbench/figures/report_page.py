"""The study report's page furniture: its style sheet and its one small script (report.py
fills the page). Inline, so that the page opens from the file system with no network."""

STYLE = """
body { font: 14px/1.45 system-ui, -apple-system, "Segoe UI", sans-serif; margin: 1.5em auto;
       max-width: 1400px; padding: 0 1em; color: #1d1f21; }
h1 { margin-bottom: 0.2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #ddd; }
.meta { color: #555; }
code, pre { font: 12px/1.4 ui-monospace, "DejaVu Sans Mono", monospace; }
pre { background: #f6f8fa; padding: 0.8em; overflow-x: auto; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #d6d8da; padding: 2px 6px; text-align: right; white-space: nowrap; }
th { background: #f0f2f4; position: sticky; top: 0; text-align: left; }
td.t, th.t { text-align: left; }
#runs th { cursor: pointer; user-select: none; }
#runs th[aria-sort=ascending]::after { content: " \\25B2"; }
#runs th[aria-sort=descending]::after { content: " \\25BC"; }
tr.failed td { background: #fde8e8; } tr.pending td { color: #888; }
.scroll { max-height: 80vh; overflow: auto; border: 1px solid #ddd; }
figure { display: inline-block; margin: 0.5em 1% 0.5em 0; vertical-align: top; width: 48%; }
figure.big { width: 98%; }
figure img { width: 100%; border: 1px solid #eee; cursor: zoom-in; }
figure.big img { cursor: zoom-out; }
figcaption { color: #555; font-size: 12px; }
td code { user-select: all; }
"""

# Click a figure to see it at the page's width (again: back). Click a heading of the runs
# table to sort by it (again: the other way): numbers as numbers, "-" (no value) last.
SCRIPT = """
(function () {
  document.querySelectorAll("figure img").forEach(function (img) {
    img.addEventListener("click", function () { img.parentNode.classList.toggle("big"); });
  });
  var table = document.getElementById("runs");
  if (!table) return;
  var heads = table.tHead.rows[0].cells;
  function key(cell) {
    var s = cell.textContent.trim(), x = parseFloat(s);
    return {s: s, x: (s === "-" || s === "") ? null : (isNaN(x) || !isFinite(s) ? NaN : x)};
  }
  function sortBy(col) {
    var th = heads[col], up = th.getAttribute("aria-sort") !== "ascending";
    for (var i = 0; i < heads.length; i++) heads[i].removeAttribute("aria-sort");
    th.setAttribute("aria-sort", up ? "ascending" : "descending");
    var body = table.tBodies[0], rows = Array.prototype.slice.call(body.rows);
    var keyed = rows.map(function (r, i) { return [key(r.cells[col]), i, r]; });
    var numeric = keyed.every(function (k) { return k[0].x === null || !isNaN(k[0].x); });
    keyed.sort(function (a, b) {
      var p = a[0], q = b[0], d;
      if (p.x === null || q.x === null) d = (p.x === null) - (q.x === null);
      else {
        d = numeric ? p.x - q.x : p.s.localeCompare(q.s, undefined, {numeric: true});
        if (!up) d = -d;
      }
      return d || a[1] - b[1];
    });
    var sorted = document.createDocumentFragment();   // one reflow, not one a row
    keyed.forEach(function (k) { sorted.appendChild(k[2]); });
    body.appendChild(sorted);
  }
  for (var i = 0; i < heads.length; i++)
    heads[i].addEventListener("click", sortBy.bind(null, i));
})();
"""
