"""Cost of getme's smoothing per element and iteration (issue #5), from the
fields bench.py keeps of getme's --report: seconds, iterations, elements and
the per-iteration history (elapsed since getme_smooth() started, stage).

  ns/el-it            seconds / (elements * all iterations), in ns
  ns/el-it (stage 1)  GETMe adaptive's q_mean stage only: the time from the
                      end of its first iteration to the end of its last,
                      / (elements * (stage-1 iterations - 1)).  The first
                      iteration's elapsed also holds the setup (workspace,
                      initial qualities, validity check), which is left out;
                      with a single stage-1 iteration that one is used.
  2-thread speedup    time(1 thread) / time(2 threads) of the same method

Works on rows of old result files too (it needs no field they lack).
"""

STAGE_MEAN = 1  # GETME_STAGE_MEAN in getme.h
SMOOTHERS = {"getme": "GETMe adaptive", "paper": "GETMe adaptive, paper only",
             "laplace": "smart Laplace"}


def _ns(seconds, elements, iterations):
    if not seconds or not elements or not iterations or seconds <= 0:
        return None
    return seconds * 1e9 / (elements * iterations)


def stage1(history):
    """(iterations, seconds from getme_smooth()'s start to the stage's end,
    seconds of its iterations after the first) of the q_mean stage."""
    times = [h["elapsed"] for h in history or () if h.get("stage") == STAGE_MEAN]
    if not times:
        return 0, None, None
    steady = times[-1] - times[0] if len(times) > 1 else times[0]
    return len(times), times[-1], steady


def cost_fields(row):
    """ns/el-it of a getme/laplace row (and its stage-1 figures for GETMe
    adaptive); {} for rows of other tools or failed runs."""
    if row.get("status") != "ok" or not is_smoother(row):
        return {}
    iters = (row.get("iterations_mean") or 0) + (row.get("iterations_min") or 0)
    out = {"threads": threads(row),
           "ns_el_it": _ns(row.get("seconds"), row.get("elements"), iters)}
    if smoother(row) in ("getme", "paper"):
        n1, end, steady = stage1(row.get("history"))
        out.update({"stage1_iterations": n1, "stage1_seconds": end,
                    "ns_el_it_stage1": _ns(steady, row.get("elements"),
                                           n1 - 1 if n1 > 1 else n1)})
    return out


def smoother(row):
    """'getme' or 'laplace' for getme's own methods (also sweep rows such as
    'getme-1-tf=0.005'), else None."""
    name = row.get("method", "").split("-")[0]
    return name if name in SMOOTHERS else None


def is_smoother(row):
    return smoother(row) is not None


def threads(row):
    """The thread count in the method key ('getme-2' -> 2)."""
    parts = row.get("method", "").split("-")
    return int(parts[1]) if len(parts) > 1 and parts[1].isdigit() else None


def _ratio(a, b):
    return a / b if a and b else None


def speedups(rows):
    """{'getme': {...}, 'laplace': {...}}: time(1 thread) / time(2 threads),
    for GETMe also of stage 1; a method missing a run is left out."""
    by_key = {r["method"]: r for r in rows if r.get("status") == "ok"}
    out = {}
    for name in SMOOTHERS:
        one, two = by_key.get(f"{name}-1"), by_key.get(f"{name}-2")
        if not one or not two:
            continue
        s = {"total": _ratio(one.get("seconds"), two.get("seconds"))}
        if name in ("getme", "paper"):
            s["stage1"] = _ratio(one.get("ns_el_it_stage1"), two.get("ns_el_it_stage1"))
        out[name] = s
    return out


def speedup_note(speedup):
    """One line for under a case's tables."""
    parts = []
    for name, s in speedup.items():
        text = f"{SMOOTHERS[name]} {_fmt(s.get('total'))}"
        if "stage1" in s:
            text += f" (stage 1 {_fmt(s['stage1'])})"
        parts.append(text)
    return "  2-thread speedup, time(1 thread) / time(2 threads): " + (
        ", ".join(parts) if parts else "-")


def _fmt(x):
    return f"{x:.2f}x" if x else "-"
