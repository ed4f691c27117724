"""`trackbench report STUDY`: one self-contained HTML page of a study, to open from the file
system (no network, nothing beside it): its name and description, the grid, for a [search]
its limits, the study figures (plots.py plot_study, limit_figures.py) embedded as PNG data,
the failures with their reasons, and the runs' table (sortable by a click on a heading) with
the command that replays each run.

    write_report(study, out=None) -> (path, facts)   # out: default <results>/report.html

The page holds the screen's columns of the summary (summary.py SCREEN, in display units);
summary.csv beside it holds them all. 1,000 runs make a page of about 1 MB.
"""

import base64
import datetime
import html
import os
import shlex
import tempfile
from pathlib import Path

import numpy as np

from trackbench.figures.report_page import SCRIPT, STYLE
from trackbench.outputs.files.atomic import atomic_path
from trackbench.study.read.folder import study_folder

REPORT_NAME = "report.html"
_E = html.escape


def _fmt(v):
    """A table cell's text: numbers to 4 significant digits, nothing as "-"."""
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "-"
    if isinstance(v, (float, np.floating)):
        return f"{v:.4g}"
    return str(v)


def _cells(values, tag="td", cls=None):
    attr = f' class="{cls}"' if cls else ""
    return "".join(f"<{tag}{attr}>{_E(_fmt(v))}</{tag}>" for v in values)


def _table(heads, rows, attrs=""):
    """rows: lists of ready HTML cells (strings)."""
    head = "".join(f"<th>{_E(h)}</th>" for h in heads)
    body = "\n".join(f"<tr>{''.join(r)}</tr>" for r in rows)
    return f"<table{attrs}><thead><tr>{head}</tr></thead><tbody>\n{body}\n</tbody></table>"


def folder_argument(folder):
    """The results folder as a command line names it from the current directory: relative
    when it is inside it, else absolute; quoted for a shell."""
    absolute = os.path.abspath(folder)
    rel = os.path.relpath(absolute)
    return shlex.quote(absolute if rel.startswith("..") else rel)


def replay_commands(folder_arg, run_id):
    base = f"trackbench view {folder_arg} {run_id}"
    return base, base + " --web"


def _screen_columns(df):
    """(heading, tooltip, display values) of the screen's quantities present in ``df``."""
    from trackbench.outputs.quantities import BY_NAME
    from trackbench.study.read.summary import SCREEN
    out = []
    for name in SCREEN:
        q = BY_NAME[name]
        for c in q.present(df.columns):
            head = q.heading.format(q.wheel_of(c)) if q.heading else c
            tip = q.label.replace("{}", str(q.wheel_of(c) or "")) + f" ({q.unit})"
            out.append((head, tip, q.display(df[c].astype(float)).to_numpy()))
    return out


def _grid_section(study, df):
    """The study's axes and the values they take, and a [search]'s parameter and limit."""
    rows = []
    for name in study.param_names:
        vals = [v for v in dict.fromkeys(_fmt(r.params.get(name)) for r in study.runs)]
        try:
            vals.sort(key=float)
        except ValueError:
            pass
        searched = " (searched)" if study.search is not None and name == study.search.parameter else ""
        rows.append([f'<td class="t">{_E(name + searched)}</td>', f'<td class="t">{_E(", ".join(vals))}</td>',
                     f"<td>{len(vals)}</td>"])
    text = _table(["parameter", "values", "count"], rows) if rows else "<p>one run: the base scenario</p>"
    s = study.search
    if s is not None:
        text += (f"<p>[search]: the highest <b>{_E(s.parameter)}</b> in [{s.low:g}, {s.high:g}] "
                 f"(to {s.tolerance:g}) at which <b>{_E(s.quantity)}</b> &le; {s.limit:g}, "
                 f"at every grid point; the searched values are in the runs' table.</p>")
    toml = Path(study.output) / "study.toml"
    if toml.is_file():
        text += f"<details><summary>the study file</summary><pre>{_E(toml.read_text())}</pre></details>"
    return text


def _limits_section(study, folder, folder_arg):
    """limits.csv with the command that replays the run at each limit ('' without a search)."""
    import pandas as pd

    from trackbench.study.read.limits import LIMIT_COLUMNS, LIMITS_FILE
    path = Path(folder) / LIMITS_FILE
    if study.search is None:
        return ""
    if not path.is_file():
        return f"<h2>Limits</h2><p>no {LIMITS_FILE} yet: the search has not finished a round</p>"
    lim = pd.read_csv(path)
    axes = [c for c in lim.columns if c not in LIMIT_COLUMNS]
    rows = []
    for k, rec in enumerate(lim.to_dict("records"), 1):
        run = rec.get("limit_run")
        cmd = (f"<code>trackbench view {folder_arg} --limit {k} --web</code>"
               if isinstance(run, str) and run else "-")
        rows.append([f"<td>{k}</td>", _cells([rec[a] for a in axes]), _cells([rec["search_value"]]),
                     _cells([rec["status"]], cls="t"), _cells([rec["runs"]]), _cells([run], cls="t"),
                     f'<td class="t">{cmd}</td>'])
    heads = ["point", *axes, f"limit {study.search.parameter}", "status", "runs", "run at the limit",
             "replay"]
    return f"<h2>Limits</h2>{_table(heads, rows)}"


def _figures_section(folder):
    """The study figures as embedded PNGs (plot_study into a temporary folder)."""
    from trackbench.figures.study_figures import plot_study
    with tempfile.TemporaryDirectory(prefix="trackbench-report-") as tmp:
        try:
            paths = plot_study(folder, tmp)
        except (ImportError, ValueError, FileNotFoundError) as e:
            return f"<h2>Figures</h2><p>no figures: {_E(str(e))}</p>", 0
        figs = []
        for p in paths:
            data = base64.b64encode(Path(p).read_bytes()).decode("ascii")
            figs.append(f'<figure><img alt="{_E(p.stem)}" src="data:image/png;base64,{data}">'
                        f"<figcaption>{_E(p.name)}</figcaption></figure>")
    return "<h2>Figures</h2><p>Click a figure to enlarge it.</p>\n" + "\n".join(figs), len(figs)


def _failures_section(df, params):
    bad = df[df["status"].astype(str) == "failed"]
    if bad.empty:
        return "<h2>Failures</h2><p>none</p>"
    rows = [[f'<td class="t">{_E(r["run_id"])}</td>', _cells([r[p] for p in params]),
             f'<td class="t">{_E(str(r["status_message"]))}</td>'] for _, r in bad.iterrows()]
    return f"<h2>Failures ({len(bad)})</h2>" + _table(["run", *params, "reason"], rows)


def _runs_section(df, params, folder_arg):
    """Every run: id, status, parameters, the screen's quantities, wall time, replay commands."""
    cols = _screen_columns(df)
    heads = "".join([f'<th class="t">{h}</th>' for h in ("run", "status")]
                    + [f"<th>{_E(p)}</th>" for p in params]
                    + [f'<th title="{_E(tip)}">{_E(h)}</th>' for h, tip, _ in cols]
                    + ['<th>wall s</th><th class="t">replay: the viewer, or a browser</th>'])
    values = [df[p].to_numpy(object) for p in params] + [v for _, _, v in cols]
    wall = df["wall_time"].astype(float).to_numpy()
    rows = []
    for i, (run_id, status) in enumerate(zip(df["run_id"].astype(str), df["status"].astype(str))):
        plain, web = replay_commands(folder_arg, run_id)
        rows.append(f'<tr class="{_E(status)}"><td class="t">{_E(run_id)}</td><td class="t">{_E(status)}</td>'
                    f"{_cells(v[i] for v in values)}<td>{_fmt(wall[i])}</td>"
                    f'<td class="t"><code>{_E(plain)}</code> <code>{_E(web)}</code></td></tr>')
    return (f"<h2>Runs ({len(df)})</h2><p>Click a heading to sort; every column of every run is in "
            f"summary.csv.</p>\n<div class=scroll><table id=runs><thead><tr>{heads}</tr></thead><tbody>\n"
            + "\n".join(rows) + "\n</tbody></table></div>")


def _summary(study):
    """The runs' table, rebuilt from their run.json (summary.csv rewritten, as `study summary`
    does, when the folder can be written: the figures read it)."""
    from trackbench.study.read.summary import summary_frame, write_summary
    try:
        return write_summary(study)[0]
    except OSError:
        return summary_frame(study)


def _page(study, df, sections):
    from trackbench.version import __version__
    counts = df["status"].astype(str).value_counts()
    told = ", ".join(f"{counts[s]} {s}" for s in ("completed", "failed", "pending") if counts.get(s, 0))
    when = datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{_E(study.name)}: trackbench study</title><style>{STYLE}</style></head><body>\n"
            f"<h1>{_E(study.name)}</h1><p>{_E(study.description or '')}</p>\n"
            f'<p class="meta">{len(df)} runs: {_E(told)}. Results in {_E(os.path.abspath(study.output))}; '
            f"written {when} by trackbench {_E(__version__)}.</p>\n"
            + "\n".join(s for s in sections if s)
            + f"\n<script>{SCRIPT}</script>\n</body></html>\n")


def write_report(path, out=None):
    """The report of the study at ``path`` (study file or results folder) written to ``out``
    (default <results>/report.html; a folder: report.html in it) whole or not at all. Returns
    (the path, {"runs": n, "figures": n, "failed": n, "bytes": n}). StudyError when the study
    or its results are missing."""
    study, folder = study_folder(path)
    df = _summary(study)
    params = list(study.param_names)
    arg = folder_argument(folder)
    figures, n_figures = _figures_section(folder)
    sections = [f"<h2>Grid</h2>{_grid_section(study, df)}", _limits_section(study, folder, arg), figures,
                _failures_section(df, params), _runs_section(df, params, arg)]
    page = _page(study, df, sections).encode("utf-8")
    out = Path(folder if out is None else out)
    out = out / REPORT_NAME if out.is_dir() else out
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        Path(tmp).write_bytes(page)
    failed = int((df["status"].astype(str) == "failed").sum())
    return out, {"runs": len(df), "figures": n_figures, "failed": failed, "bytes": len(page)}
