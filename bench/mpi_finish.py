#!/usr/bin/python3
"""getme-mpi's finishing step before/after the sub-mesh finishing (issue
#14): rank 0's peak RSS (whole process, /usr/bin/time per rank) and the
finishing step's wall time, two getme-mpi builds interleaved per mesh and
rank count; the outputs must have the same bytes.

usage: bench/mpi_finish.py MESH [MESH...] --before GETME_MPI --after GETME_MPI
                           [--ranks 1,2,4] [--out FILE.md] [--json FILE]

The finishing time is what getme-mpi logs ("finishing N passes in S s"):
before, rank 0's gather-free whole-mesh workspace build + passes; after,
candidate selection, gathers, sub-mesh passes and the broadcast.  This
machine has 2 cores shared with others: compare before/after within a row.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

FIN = re.compile(r"finishing (\d+) passes in ([\d.]+) s")
SUB = re.compile(r"sub-mesh of (\d+) elements \((\d+) node copies gathered, (\d+) tr")
DONE = re.compile(r"Done \(([\d.]+) s in all\)")


def run(exe, mesh, ranks, out, tmp):
    env = dict(os.environ, OMP_WAIT_POLICY="passive", OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    rss = os.path.join(tmp, "rss")
    cmd = ["mpirun", "--oversubscribe", "-np", str(ranks), "sh", "-c",
           f'exec /usr/bin/time -f %M -o {rss}.$OMPI_COMM_WORLD_RANK "$@"', "sh",
           exe, "smooth", mesh, "-o", out, "-v"]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode:
        sys.exit(f"getme-mpi failed: {p.stderr}")
    fin = FIN.search(p.stdout)
    sub = SUB.search(p.stdout)
    peak = [int(open(f"{rss}.{r}").read().split()[-1]) / 1024.0 for r in range(ranks)]
    return {"passes": int(fin.group(1)), "finish_s": float(fin.group(2)),
            "total_s": float(DONE.search(p.stdout).group(1)),
            "sub_elements": int(sub.group(1)) if sub else None,
            "sub_tries": int(sub.group(3)) if sub else None,
            "rss_mib": peak}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="+")
    ap.add_argument("--before", required=True)
    ap.add_argument("--after", required=True)
    ap.add_argument("--ranks", default="1,2,4")
    ap.add_argument("--out")
    ap.add_argument("--json")
    a = ap.parse_args()
    lines = ["| mesh | ranks | finishing s before | after | rank 0 peak RSS MiB "
             "before | after | other ranks' peak MiB after | sub-mesh elements "
             "(tries) | same bytes |", "|---|---|---|---|---|---|---|---|---|"]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in a.meshes:
            name = os.path.basename(mesh).split("-g")[0]
            ext = os.path.splitext(mesh)[1]
            for ranks in (int(r) for r in a.ranks.split(",")):
                ob, oa = os.path.join(tmp, "b" + ext), os.path.join(tmp, "a" + ext)
                b = run(a.before, mesh, ranks, ob, tmp)
                f = run(a.after, mesh, ranks, oa, tmp)
                same = open(ob, "rb").read() == open(oa, "rb").read()
                rows.append({"mesh": name, "ranks": ranks, "before": b, "after": f,
                             "same_bytes": same})
                others = "/".join(f"{x:.0f}" for x in f["rss_mib"][1:]) or "-"
                lines.append(f"| {name} | {ranks} | {b['finish_s']:.2f} | "
                             f"{f['finish_s']:.2f} | {b['rss_mib'][0]:.0f} | "
                             f"{f['rss_mib'][0]:.0f} | {others} | "
                             f"{f['sub_elements']} ({f['sub_tries']}) | "
                             f"{'yes' if same else 'NO'} |")
                print(lines[-1], flush=True)
    if a.out:
        with open(a.out, "w") as fo:
            fo.write("\n".join(lines) + "\n")
    if a.json:
        with open(a.json, "w") as fo:
            json.dump(rows, fo, indent=1)


if __name__ == "__main__":
    main()
