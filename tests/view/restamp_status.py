#!/usr/bin/env python3
"""Copies the STATUS_* events of an LCM log into a new log, spread evenly over the span of a reference log.

A process run from a log through LCM's file provider stamps its STATUS with the wall clock; the view test
plays that STATUS beside the sensor log, so it moves them onto the sensor log's time span.
  restamp_status.py IN.lcmlog OUT.lcmlog REFERENCE.lcmlog
"""
import struct
import sys

SYNC = 0xEDA1DA01


def events(path):
    with open(path, "rb") as f:
        data = f.read()
    pos = 0
    while pos + 28 <= len(data):
        sync, number, stamp, channel_len, data_len = struct.unpack_from(">IqqII", data, pos)
        if sync != SYNC:
            raise SystemExit(f"{path}: bad sync word at {pos}")
        pos += 28
        channel = data[pos:pos + channel_len]
        payload = data[pos + channel_len:pos + channel_len + data_len]
        pos += channel_len + data_len
        yield channel, payload, stamp


def main():
    src, dst, reference = sys.argv[1], sys.argv[2], sys.argv[3]
    stamps = [t for _, _, t in events(reference)]
    first, last = min(stamps), max(stamps)
    status = [(c, p) for c, p, _ in events(src) if c.startswith(b"STATUS_")]
    if not status:
        raise SystemExit(f"{src}: no STATUS_ event")
    with open(dst, "wb") as f:
        for i, (channel, payload) in enumerate(status):
            stamp = first + (last - first) * (i + 1) // (len(status) + 1)
            f.write(struct.pack(">IqqII", SYNC, i, stamp, len(channel), len(payload)) + channel + payload)


main()
