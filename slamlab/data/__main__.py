"""``python -m slamlab.data list | fetch [SET ...] | verify [SET ...] | mirror DIR``: see :mod:`slamlab.data`."""

from __future__ import annotations

import argparse
import sys

from .commands import fetch_sets, list_sets, make_mirror, verify, verify_report
from .fetch import DataFetchError


def main(argv: list[str] | None = None) -> int:
    """Run one data command; returns the exit status (0 ok, 1 a check failed, 2 a fetch failed)."""
    parser = argparse.ArgumentParser(prog="python -m slamlab.data", description=__doc__.split(":")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="the sets: files, size, licence, where each is found")
    p = sub.add_parser("fetch", help="fetch what no data folder holds (every set by default)")
    p.add_argument("sets", nargs="*", metavar="SET")
    p = sub.add_parser("verify", help="re-hash every registered file found; exit 1 unless all are found and match")
    p.add_argument("sets", nargs="*", metavar="SET")
    p.add_argument("--files", action="store_true", help="print every file, not only those that do not match")
    p = sub.add_parser("mirror", help="write every upstream file under DIR/<host>/<path> (fetching what is missing)")
    p.add_argument("dir", metavar="DIR")
    args = parser.parse_args(argv)
    try:
        if args.command == "list":
            print(list_sets())
        elif args.command == "fetch":
            print(fetch_sets(args.sets))
        elif args.command == "verify":
            text, ok = verify_report(verify(args.sets), every_file=args.files)
            print(text)
            return 0 if ok else 1
        else:
            print(make_mirror(args.dir))
    except DataFetchError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except ValueError as err:
        parser.error(str(err))
    return 0


if __name__ == "__main__":
    sys.exit(main())
