"""PNG plots of one benchmark case: q*_min and q_mean against smoothing time
(the paper's Figs. 6 and 9) and a quality histogram per method."""

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STYLE = {"getme": "-", "laplace": "--"}


def plot_quality_time(case, path, cpu):
    """Left q*_min, right q_mean against seconds.  Methods with per-iteration
    history are lines; tools that only give an end point are markers."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    init = case["initial"]
    for ax, key, name in ((axes[0], "q_min_star", "q*min"),
                          (axes[1], "q_mean", "q_mean")):
        ax.axhline(init[key], color="0.6", lw=0.8, ls=":", label="initial")
        for row in case["rows"]:
            if row.get("status") != "ok" or row["method"] == "initial":
                continue
            hist = row.get("history") or []
            if hist:
                t = [0.0] + [h["elapsed"] for h in hist]
                q = [init[key]] + [h[key] for h in hist]
                style = STYLE["laplace" if "laplace" in row["method"] else "getme"]
                ax.plot(t, q, style, lw=1.4, label=row["label"])
            else:
                ax.plot([row["seconds"]], [row[key]], "o", ms=6, label=row["label"])
        ax.set_xlabel("smoothing time [s]")
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    axes[1].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"{case['title']}\n{cpu}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_histogram(case, path):
    """Element counts per 0.1 quality bin, one bar group per bin."""
    rows = [case["initial_row"]] + [r for r in case["rows"]
                                    if r.get("status") == "ok" and r.get("histogram")]
    fig, ax = plt.subplots(figsize=(11, 4.2))
    width = 0.8 / max(1, len(rows))
    x = np.arange(10)
    for i, row in enumerate(rows):
        counts = np.asarray(row["histogram"], dtype=float)
        counts[counts == 0] = np.nan  # an empty bin draws no bar
        ax.bar(x + (i - (len(rows) - 1) / 2) * width, counts, width, label=row["label"])
    ax.set_yscale("log")
    ax.set_ylim(bottom=0.7)
    ax.set_xticks(x, [f"{b / 10:.1f}-{(b + 1) / 10:.1f}" for b in range(10)])
    ax.set_xlabel("mean ratio quality")
    ax.set_ylabel("elements (log)")
    ax.set_title(case["title"], fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_scaling(summary, path, cpu):
    """ns per element-iteration of GETMe adaptive's stage 1 against the
    element count (log x), one line per case and thread count."""
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    colors = {}
    for s in summary:
        if s["field"] != "ns_el_it_stage1":
            continue
        color = colors.setdefault(s["case"], f"C{len(colors)}")
        sizes = sorted(s["values"], key=s["elements"].get)
        x = [s["elements"][z] for z in sizes]
        y = [s["values"][z] for z in sizes]
        ax.plot(x, y, "-o" if s["threads"] == 1 else "--s", color=color, lw=1.4, ms=5,
                label=f"{s['case']}, {s['threads']} thread{'s' * (s['threads'] > 1)}")
        for xi, yi, z in zip(x, y, sizes):
            ax.annotate(z, (xi, yi), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("elements")
    ax.set_ylabel("ns per element-iteration, GETMe stage 1")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title(f"getme stage-1 cost against mesh size\n{cpu}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
