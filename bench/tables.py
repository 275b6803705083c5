"""Tables like the paper's Tables 1-2: text for the terminal (and a .txt /
.md file), CSV and JSON for machines."""

import csv
import json

COLUMNS = [  # (header, row key, format)
    ("Method", "label", "{}"),
    ("Mem GiB", "peak_gib", "{:.3f}"),
    ("dMem GiB", "delta_gib", "{:.3f}"),
    ("Time s", "seconds", "{:.2f}"),
    ("Iter", "iterations", "{}"),
    ("ns/el-it", "ns_el_it", "{:.1f}"),
    ("q*min", "q_min_star", "{:.4f}"),
    ("q_mean", "q_mean", "{:.4f}"),
    ("#q<=0.4", "n_le_04", "{}"),
    ("#q<0.1", "n_lt_01", "{}"),
    ("#invalid", "invalid", "{}"),
    ("Elements", "elements", "{}"),
    ("Nodes", "nodes", "{}"),
    ("Topology changed", "topology", "{}"),
]

CSV_FIELDS = ["size", "case", "method", "label", "status", "peak_gib",
              "delta_gib", "seconds", "wall", "iterations_mean",
              "iterations_min", "q_min_star", "q_min", "q_mean", "n_le_04",
              "n_lt_01", "invalid", "elements", "nodes", "free_nodes",
              "topology", "report_q_min_star", "report_q_mean", "threads",
              "ns_el_it", "stage1_iterations", "stage1_seconds",
              "ns_el_it_stage1", "speedup_2t", "speedup_2t_stage1"]

COST_COLUMNS = [  # the "Cost and scaling" table of getme's own methods
    ("Method", "label", "{}"),
    ("Elements", "elements", "{}"),
    ("Time s", "seconds", "{:.2f}"),
    ("Iter", "iterations", "{}"),
    ("ns/el-it", "ns_el_it", "{:.1f}"),
    ("Stage-1 it", "stage1_iterations", "{}"),
    ("ns/el-it (stage 1)", "ns_el_it_stage1", "{:.1f}"),
    ("Speedup 1/2 thr", "speedup_2t", "{:.2f}x"),
]


def _cell(row, key, fmt):
    value = row.get(key)
    if value is None or value == "":
        return "-"
    try:
        return fmt.format(value)
    except (ValueError, TypeError):
        return str(value)


def format_table(title, rows, notes=(), columns=COLUMNS, last_text=True):
    """Fixed-width text table with a title line and note lines under it
    (numbers right-aligned; the first column and, if last_text, the last
    are text, left-aligned)."""
    cells = [[h for h, _, _ in columns]]
    for row in rows:
        if row.get("status", "ok") != "ok":
            cells.append([row["label"], row["status"]] + [""] * (len(columns) - 2))
        else:
            cells.append([_cell(row, k, f) for _, k, f in columns])
    widths = [max(len(r[i]) for r in cells if i < len(r)) for i in range(len(columns))]
    widths[1] = max(len(columns[1][0]), 7)  # status text may overflow
    lines = [title]
    for r in cells:
        parts = [r[0].ljust(widths[0])]
        numbers = slice(1, -1) if last_text else slice(1, None)
        parts += [c.rjust(w) for c, w in zip(r[numbers], widths[numbers])]
        if last_text:
            parts.append(r[-1])
        lines.append("  ".join(parts).rstrip())
    lines.extend(notes)
    return "\n".join(lines)


def format_cost_table(title, rows, notes=()):
    """The small "Cost and scaling" table: time per element-iteration of
    getme's own methods (see cost.py)."""
    return format_table(title, rows, notes, columns=COST_COLUMNS, last_text=False)


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for row in rows:
            w.writerow({k: row.get(k, "") for k in CSV_FIELDS})


def write_json(path, data):
    with open(path, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
