#!/usr/bin/env python3
"""Records the states of a running hapticd for a while (2 s by default) to a CSV with the
daemon's --record columns, one row per state received, in tick order.

    python3 client/python/examples/record_states.py states.csv
    python3 client/python/examples/record_states.py states.csv --seconds 5 --port 47100

Exit 0 with "recorded N states (ticks A..B) to FILE", 1 when no daemon answered or no state came,
2 for a bad command line.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import hapticd_client  # noqa: E402  (found next to this folder)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the CSV to write")
    parser.add_argument("--seconds", type=float, default=2.0, help="how long (default 2)")
    parser.add_argument("--host", default="127.0.0.1", help="daemon address (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=hapticd_client.DEFAULT_PORT,
                        help="daemon UDP port (default 47100)")
    parser.add_argument("--key-file", help="pre-shared key file, 64 hex digits")
    args = parser.parse_args()
    if not args.seconds >= 0:
        parser.error("--seconds must be a number >= 0")
    key = hapticd_client.load_key(args.key_file) if args.key_file else None
    try:
        with hapticd_client.Client.connect(args.host, args.port, key=key,
                                           name="record_states.py") as c:
            # every tick the daemon's network thread sees, at its tick rate (at most 1000 a second)
            rate = min(c.welcome["tick_rate_hz"] or 1000, c.welcome["max_state_rate_hz"] or 1000)
            c.subscribe(rate, each_tick=True)
            states = sorted(c.states(args.seconds), key=lambda s: s["tick"])
    except hapticd_client.HapticdError as e:
        print(f"record_states.py: {e}", file=sys.stderr)
        return 1
    if not states:
        print("record_states.py: no state came from the daemon", file=sys.stderr)
        return 1
    hapticd_client.write_record(args.out, states)
    print(f"recorded {len(states)} states (ticks {states[0]['tick'] - 1}.."
          f"{states[-1]['tick'] - 1}) to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
