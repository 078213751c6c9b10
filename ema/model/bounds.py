"""Bounds on what a window says of itself, in one place and without numpy (the command line's help reads them)."""

from __future__ import annotations

import datetime as dt

IDENTIFIER = r"^[!-~](?:[ -~]{0,198}[!-~])?$"  # printable ASCII, no surrounding blanks: safe in a URL and a CSV
# Times a trend computes with, bounded where they enter: no airframe flies a million hours, no log predates
# 2000 or is stamped more than a day ahead of the clock that receives it.
MAX_FLIGHT_HOURS = 1_000_000.0
EARLIEST_RECORDED_AT = dt.datetime(2000, 1, 1, tzinfo=dt.UTC)
CLOCK_SKEW = dt.timedelta(days=1)
