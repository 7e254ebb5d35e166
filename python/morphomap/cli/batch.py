"""``morphomap batch``: the pairs of a manifest mapped on Dask distributed."""

from __future__ import annotations

import os
import sys

from distributed import Client

from ..batch import map_batch
from ..batch_manifest import SUMMARY_NAME, read_manifest
from ..mapping import CURVE_METHODS
from ..surfaces import SURFACE_METHODS


def run(args, parser) -> int:
    try:
        jobs = read_manifest(args.manifest, args.out, method=args.method, spacing=args.spacing, smooth=args.smooth,
                             methods=sorted(set(CURVE_METHODS) | set(SURFACE_METHODS)))
    except OSError as error:
        parser.error(f"cannot read {args.manifest}: {error.strerror or error}")
    except ValueError as error:
        parser.error(str(error))
    os.makedirs(args.out, exist_ok=True)
    client = None
    if args.scheduler:
        client = Client(args.scheduler)
    summary = os.path.join(args.out, SUMMARY_NAME)
    try:
        results = map_batch(jobs, client=client, workers=args.workers, summary=summary,
                            progress=False if args.no_progress else None)
    finally:
        if client is not None:
            client.close()
    for r in results:
        name = f"{r.job.label}: " if r.job.label else ""
        print(f"{r.status:8s} {name}{r.job.c1} -> {r.job.c2}: {r.message}", file=sys.stderr)
    failed = sum(r.status == "failed" for r in results)
    skipped = sum(r.status == "skipped" for r in results)
    print(f"{len(results)} jobs: {len(results) - failed} done or skipped, {failed} failed ({skipped} skipped: inputs "
          f"and options unchanged); fields and {SUMMARY_NAME} in {args.out}", file=sys.stderr)
    return 1 if failed else 0
