#!/usr/bin/env python3
"""An unsigned .vcase that expands to ~1 GiB, to time how fast the player refuses it (issue 58).

Four 255 MiB entries listed in a valid manifest (true sizes, CRCs and SHA-256s), no
signature.json. Each entry is one 1 MiB chunk of sparse noise compressed once with a full flush
and repeated, so the file takes seconds to write, and its expansion (~90:1) stays under the
package's ratio limit (200:1): only the missing signature can refuse it.

    bench/trust/make_unsigned_bomb.py OUT.vcase
"""
import hashlib
import json
import random
import struct
import sys
import zlib

CHUNK = 1 << 20
ENTRY_CHUNKS = 255
ENTRIES = 4


def chunk_bytes():
    rnd = random.Random(58)
    data = bytearray(CHUNK)
    for i in range(0, CHUNK, 256):  # one random byte in 256: about 90:1
        data[i] = rnd.randrange(256)
    return bytes(data)


def deflated(chunk):
    comp = zlib.compressobj(9, zlib.DEFLATED, -15)
    body = comp.compress(chunk) + comp.flush(zlib.Z_FULL_FLUSH)  # independent of what came before
    tail = zlib.compressobj(9, zlib.DEFLATED, -15).flush(zlib.Z_FINISH)  # an empty final block
    return body, tail


def entry_facts(chunk):
    crc, sha = 0, hashlib.sha256()
    for _ in range(ENTRY_CHUNKS):
        crc = zlib.crc32(chunk, crc)
        sha.update(chunk)
    return crc & 0xFFFFFFFF, sha.hexdigest()


def local_header(name, method, crc, csize, usize):
    return struct.pack("<IHHHHHIIIHH", 0x04034B50, 20, 0, method, 0, 0x21, crc, csize, usize, len(name), 0) + name


def central_header(name, method, crc, csize, usize, offset):
    return struct.pack("<IHHHHHHIIIHHHHHII", 0x02014B50, 0x0314, 20, 0, method, 0, 0x21, crc, csize, usize,
                       len(name), 0, 0, 0, 0, 0o100644 << 16, offset) + name


def main(out):
    chunk = chunk_bytes()
    body, tail = deflated(chunk)
    crc, sha = entry_facts(chunk)
    usize, csize = CHUNK * ENTRY_CHUNKS, len(body) * ENTRY_CHUNKS + len(tail)
    names = [f"payload/part{i}.bin" for i in range(ENTRIES)]
    manifest = json.dumps({
        "schemaVersion": 1, "caseId": "bomb", "caseVersion": "1.0.0", "minPlayerVersion": "0.1.0",
        "features": ["xpbd"], "units": {"length": "m", "mass": "kg", "time": "s"}, "device": {}, "files": [{"path": n, "size": usize, "sha256": sha} for n in names]}).encode()
    mcrc = zlib.crc32(manifest) & 0xFFFFFFFF
    central, offset = [], 0
    with open(out, "wb") as f:
        def put(b):
            nonlocal offset
            f.write(b)
            offset += len(b)
        start = offset
        put(local_header(b"manifest.json", 0, mcrc, len(manifest), len(manifest)) + manifest)
        central.append(central_header(b"manifest.json", 0, mcrc, len(manifest), len(manifest), start))
        for n in names:
            start = offset
            put(local_header(n.encode(), 8, crc, csize, usize))
            for _ in range(ENTRY_CHUNKS):
                put(body)
            put(tail)
            central.append(central_header(n.encode(), 8, crc, csize, usize, start))
        cd_start = offset
        for c in central:
            put(c)
        put(struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(central), len(central), offset - cd_start, cd_start, 0))
    print(f"{out}: {offset} bytes, expands to {usize * ENTRIES} bytes ({usize * ENTRIES / offset:.0f}:1)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_unsigned_bomb.py OUT.vcase")
    main(sys.argv[1])
