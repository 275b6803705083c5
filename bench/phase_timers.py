#!/usr/bin/env python3
"""Instrument a scratch copy of getme with phase timers (a measurement tool).

    git worktree add /work/exp HEAD
    /usr/bin/python3 bench/phase_timers.py /work/exp
    cmake -S /work/exp -B /work/exp/build -DCMAKE_BUILD_TYPE=Release
    cmake --build /work/exp/build -j2 --target getme_cli
    OMP_NUM_THREADS=2 /work/exp/build/cli/getme smooth IN.msh -o /tmp/o.msh 2>&1 |
      awk '/^TT/ {t[substr($0, 13)] += $2} END {for (k in t) printf "%8.4f %s\n", t[k], k}'

Inserts `TT(name)` calls that print "TT <seconds since the last mark>
<name>" to stderr at the steps of the reader's workspace and boundary
search (since session 27), of each sweep of the quality measures, of
the set-up (getme__adj_build, the run's arrays, the first qualities,
the blocks' edge lists, the Eq. 9 sums), of every iteration (scatter,
new nodes, relaxation, update of the sums) and of the q*min stage's
cycles and finishing step, and (since session 28) of the block sweeps'
phases (getme__blocks_run: each level of the parts, then the colours,
summed over all sweeps, on block_local.c's own clock).  Nothing else
changes: the output file is the same bits (cmp it against the
uninstrumented build).

Never run it on the main checkout: the library must not print (a
library-first rule), and these prints are for one measurement.  The
anchors are lines of the sources as of session 24; an anchor that no
longer matches is reported and skipped, so a partly instrumented build
still measures what it can.
"""

import os
import sys

MACROS = (
    "\n#include <omp.h>\n#include <stdio.h>\n"
    "static double TT_t0;\n"
    "#define TT(name) do { double TT_n = omp_get_wtime(); "
    "fprintf(stderr, \"TT %8.4f %s\\n\", TT_n - TT_t0, name); "
    "TT_t0 = TT_n; } while (0)\n"
    "#define TT0() (TT_t0 = omp_get_wtime())\n"
)

# file -> [(anchor, replacement)]: each anchor's first occurrence
PATCHES = {
    "core/src/workspace.c": [
        ("    if (mesh->mirror < 0)\n        getme__detect_orientation(mesh);\n    ws->dim",
         "    TT0();\n    if (mesh->mirror < 0)\n        getme__detect_orientation(mesh);\n"
         "    ws->dim"),
        ("    if ((st = number_nodes(ws, mesh, renumber)) != GETME_OK)\n        goto fail;",
         "    TT(\"ws: order_elements\");\n"
         "    if ((st = number_nodes(ws, mesh, renumber)) != GETME_OK)\n        goto fail;\n"
         "    TT(\"ws: number_nodes\");"),
        ("    if ((st = build_stars(ws)) != GETME_OK)\n        goto fail;\n    read_fixed(ws, mesh);",
         "    TT(\"ws: coordinates\");\n    if ((st = build_stars(ws)) != GETME_OK)\n"
         "        goto fail;\n    TT(\"ws: build_stars\");\n    read_fixed(ws, mesh);"),
        ("    if ((st = cut_blocks(ws)) != GETME_OK)\n        goto fail;\n    return GETME_OK;",
         "    TT(\"ws: read_fixed\");\n    if ((st = cut_blocks(ws)) != GETME_OK)\n"
         "        goto fail;\n    TT(\"ws: cut_blocks\");\n    return GETME_OK;"),
    ],
    "core/src/topology.c": [
        ("    int64_t foff[GETME_NUM_TYPES];\n    int64_t total = getme__ws_face_offsets(&ws, foff);",
         "    TT0();\n    int64_t foff[GETME_NUM_TYPES];\n"
         "    int64_t total = getme__ws_face_offsets(&ws, foff);"),
        ("    const getme_facenb *fnb = &ws.faces;",
         "    TT(\"boundary: faces, pack\");\n    const getme_facenb *fnb = &ws.faces;"),
        ("    free(touch);\n",
         "    free(touch);\n    TT(\"boundary: touch, mark\");\n"),
    ],
    "core/src/block_local.c": [
        # getme__blocks_run's phases (session 28): the parts' levels and
        # the colours, summed over every block sweep (scatter, first trial
        # pass, Eq. 9 sums); this file's own clock, so the other files'
        # timers keep their meaning
        ("    int64_t total = 0;\n    int np = blk->num_parts;\n",
         "    int64_t total = 0;\n    int np = blk->num_parts;\n    TT0();\n"),
        ("            feed_level(fb, ptr, np);\n    }\n",
         "            feed_level(fb, ptr, np);\n"
         "        if (l == 0)\n            TT(\"blocks: level 0\");\n"
         "        else if (l == 1)\n            TT(\"blocks: level 1\");\n"
         "        else\n            TT(\"blocks: level 2+\");\n    }\n"),
        ("            total += f(ctx, blk->order[k]);\n    }\n    return total;",
         "            total += f(ctx, blk->order[k]);\n    }\n"
         "    TT(\"blocks: colours\");\n    return total;"),
    ],
    "core/src/measures.c": [
        ("    int nt = omp_get_max_threads();\n    double *v =",
         "    TT0();\n    int nt = omp_get_max_threads();\n    double *v ="),
        ("    free(v);\n    free(part);\n    return GETME_OK;\n}",
         "    TT(\"measures: one sweep\");\n    free(v);\n    free(part);\n"
         "    return GETME_OK;\n}"),
    ],
    "core/src/smooth.c": [
        ("    getme__ws_lend_conn(&ws, mesh); /* back at done: */",
         "    TT0();\n    getme__ws_lend_conn(&ws, mesh); /* back at done: */"),
        ("    run.adj = &adj;\n    run.params = params;",
         "    TT(\"adj_build\");\n    run.adj = &adj;\n    run.params = params;"),
        ("    getme__ws_qualities(&ws, run.q);\n",
         "    TT(\"run_alloc\");\n    getme__ws_qualities(&ws, run.q);\n    TT(\"qualities\");\n"),
        ("    getme__stars_pack(&ws);      /* read node by node from here on */",
         "    getme__stars_pack(&ws);      /* read node by node from here on */\n"
         "    TT(\"checks/lend/pack\");"),
        ("    getme__ws_unpack_map(&ws); /* into the stars' array: no allocation */",
         "    TT0();\n    getme__ws_unpack_map(&ws); /* into the stars' array: no allocation */"),
        ("    result->seconds = omp_get_wtime() - t0;",
         "    TT(\"end: free, store, return\");\n    result->seconds = omp_get_wtime() - t0;"),
    ],
    "core/src/adjacency.c": [
        ("    int64_t ftotal = getme__ws_face_offsets(ws, adj->foff);",
         "    TT0();\n    int64_t ftotal = getme__ws_face_offsets(ws, adj->foff);"),
        ("    adj->count = getme__malloc(ne * sizeof *adj->count);",
         "    TT(\" faces\");\n    adj->count = getme__malloc(ne * sizeof *adj->count);"),
        ("    st = GETME_ERR_NOMEM;\n    if (!check) /* else fused into check_all's walk */",
         "    TT(\" build_edges\");\n    st = GETME_ERR_NOMEM;\n"
         "    if (!check) /* else fused into check_all's walk */"),
        ("    if (!(scratch = getme__malloc(sbytes)))",
         "    TT(\" counts_and_flags\");\n    if (!(scratch = getme__malloc(sbytes)))"),
        ("    if (check)\n        check_all(",
         "    TT(\" blocks_build\");\n    if (check)\n        check_all("),
        ("    free(edeg), edeg = NULL;\n    int32_t nirr = 0;",
         "    TT(\" check_all\");\n    free(edeg), edeg = NULL;\n    int32_t nirr = 0;"),
    ],
    "core/src/getme_adaptive.c": [
        ("    getme_status st = alloc_adaptive(run);\n",
         "    TT0();\n    getme_status st = alloc_adaptive(run);\n"),
        ("    lists_all(run);\n    set_bounds(run);",
         "    TT(\"a: alloc, best, input\");\n    lists_all(run);\n    set_bounds(run);"),
        ("    getme__blocks_edges(&run->adj->blk, run->adj, ws);\n",
         "    TT(\"a: lists, mark_last\");\n"
         "    getme__blocks_edges(&run->adj->blk, run->adj, ws);\n"
         "    TT(\"a: blocks_edges\");\n"),
        ("    getme__adj_sums_all(run->adj, ws, run->q);\n    run->guard",
         "    TT(\"a: slots\");\n    getme__adj_sums_all(run->adj, ws, run->q);\n"
         "    TT(\"a: sums_all\");\n    run->guard"),
        ("    run->place_early = 0;\n    if (run->comm) { /* every copy",
         "    TT(\"  i: scatter\");\n    run->place_early = 0;\n"
         "    if (run->comm) { /* every copy"),
        ("    compute_new_nodes(run, R[0]);\n",
         "    compute_new_nodes(run, R[0]);\n    TT(\"  i: new nodes\");\n"),
        ("    *num_relaxed = getme__relax(run, R, nR);\n",
         "    TT(\"  i: qold\");\n    *num_relaxed = getme__relax(run, R, nR);\n"
         "    TT(\"  i: relax\");\n"),
        ("    getme__reset_nodes(run);\n    getme_status st = mean_stage",
         "    getme__reset_nodes(run);\n    TT(\"  i: reset nodes\");\n"
         "    getme_status st = mean_stage"),
        ("    int64_t stars = 0; /* the elements around I_T, with repeats */",
         "    TT(\"   s: I_T\");\n"
         "    int64_t stars = 0; /* the elements around I_T, with repeats */"),
        ("        getme__blocks_group(&run->adj->blk, ws, run->elems, ne) == GETME_OK) {\n",
         "        getme__blocks_group(&run->adj->blk, ws, run->elems, ne) == GETME_OK) {\n"
         "        TT(\"   s: ring, group\");\n"),
        ("    if (getme__dist_any(run, tlist_reserve(run, (int64_t)run->num_t +",
         "    TT(\"   u: sums\");\n"
         "    if (getme__dist_any(run, tlist_reserve(run, (int64_t)run->num_t +"),
        ("        double prev_mean = q_mean, prev_min = q_min;\n",
         "        TT(\"iterate (rest)\");\n        double prev_mean = q_mean, prev_min = q_min;\n"),
        ("            qt = getme__threshold(run, p->threshold_fraction, 0);\n",
         "            TT(\"summary, report, best\");\n"
         "            qt = getme__threshold(run, p->threshold_fraction, 0);\n"
         "            TT(\"cycle: threshold\");\n"),
        ("            have_cycle = 1;\n",
         "            TT(\"cycle: start_tlist\");\n            have_cycle = 1;\n"),
        ("    run->tally = NULL;\n    if (best.on && best_min > q_min) {",
         "    TT(\"loop end\");\n    run->tally = NULL;\n"
         "    if (best.on && best_min > q_min) {"),
        ("    getme__summary(run, &res->q_mean, &res->q_min_star, &res->q_min);\n"
         "    if (st == GETME_OK && run->comm_failed)",
         "    TT(\"restore, revert, finish\");\n"
         "    getme__summary(run, &res->q_mean, &res->q_min_star, &res->q_min);\n"
         "    if (st == GETME_OK && run->comm_failed)"),
    ],
}


def patch(root, rel, pairs):
    path = os.path.join(root, rel)
    with open(path) as f:
        s = f.read()
    if "static double TT_t0;" in s:
        print(f"{rel}: already instrumented")
        return 0
    # after the file's first #include line
    i = s.index("#include")
    j = s.index("\n", i)
    s = s[:j] + MACROS + s[j + 1:]
    missed = 0
    for old, new in pairs:
        if old not in s:
            print(f"{rel}: anchor not found, skipped: {old.strip()[:60]!r}")
            missed += 1
            continue
        s = s.replace(old, new, 1)
    with open(path, "w") as f:
        f.write(s)
    print(f"{rel}: {len(pairs) - missed} of {len(pairs)} timers")
    return missed


def main(argv):
    if len(argv) != 2 or not os.path.isdir(os.path.join(argv[1], "core", "src")):
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    root = argv[1]
    if os.path.isdir(os.path.join(root, ".git")):  # a worktree's is a file
        print("refusing to instrument a main checkout (use a git worktree)",
              file=sys.stderr)
        return 2
    missed = sum(patch(root, rel, pairs) for rel, pairs in PATCHES.items())
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
