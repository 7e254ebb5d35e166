"""``morphomap batch``: the pairs of a manifest mapped on Dask distributed."""

from __future__ import annotations

import csv
import os
import sys

from distributed import Client

from ..batch import Job, map_batch


def run(args, parser) -> int:
    try:
        with open(args.manifest, newline="", encoding="utf-8") as handle:
            rows = [row for row in csv.reader(handle) if row and not row[0].startswith("#")]
    except OSError as error:
        parser.error(f"cannot read {args.manifest}: {error.strerror or error}")
    if rows and rows[0][:2] == ["c1", "c2"]:
        rows = rows[1:]
    base = os.path.dirname(os.path.abspath(args.manifest))
    os.makedirs(args.out, exist_ok=True)
    jobs = []
    for number, row in enumerate(rows, start=1):
        if len(row) not in (2, 3):
            parser.error(f"{args.manifest}: row {number}: expected c1,c2[,method], got {len(row)} values")
        c1, c2 = (p if os.path.isabs(p) else os.path.join(base, p) for p in row[:2])
        stem = f"{number:03d}_{os.path.splitext(os.path.basename(c1))[0]}_{os.path.splitext(os.path.basename(c2))[0]}"
        jobs.append(Job(c1, c2, os.path.join(args.out, stem + ".csv"), row[2] if len(row) == 3 else args.method,
                        args.spacing, args.smooth))
    client = None
    if args.scheduler:
        client = Client(args.scheduler)
    results = map_batch(jobs, client=client, workers=args.workers, progress=False if args.no_progress else None)
    for r in results:
        print(f"{r.status:8s} {r.job.c1} -> {r.job.c2}: {r.message}", file=sys.stderr)
    failed = sum(r.status == "failed" for r in results)
    print(f"{len(results)} jobs: {len(results) - failed} done or skipped, {failed} failed; fields in {args.out}",
          file=sys.stderr)
    return 1 if failed else 0
