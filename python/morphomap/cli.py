"""The morphomap command line."""

from __future__ import annotations

import argparse
import sys


def _info(args) -> int:
    import morphomap

    info = morphomap.build_info()
    print(f"morphomap {info['version']}")
    print(f"CGAL      {info['cgal']}")
    print(f"Embree    {info['embree']}")
    print(f"Eigen     {info['eigen']}")
    print(f"TBB       {info['tbb']}")
    print(f"threads   {info['threads']}")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="morphomap", description="Displacement fields between growing boundaries.")
    commands = parser.add_subparsers(dest="command", required=True)
    info = commands.add_parser("info", help="print the version, the libraries it was built against and the threads it uses")
    info.set_defaults(run=_info)
    args = parser.parse_args(argv)
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
