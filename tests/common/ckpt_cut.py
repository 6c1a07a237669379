#!/usr/bin/python3
"""Rewrites a checkpoint as a build that wrote fewer sections would have.

  ckpt_cut.py FILE BLOCK
  ckpt_cut.py FILE BLOCK --only

keeps the blocks of FILE's image up to and including the one called BLOCK,
drops the rest, and writes FILE again with the header's byte count and the
hash of the shorter image (the format of common/mps_ckpt.h). The restart
tests use it to make a coupler checkpoint of an implicit run without the
implicit coupling's history ("implicit", "iter*", "accel*"), as the builds
before it wrote them, and check that a restart refuses it with one line.
With --only it drops the block BLOCK alone, keeping those after it: a
solver checkpoint of a build without that particle field ("ppe_held",
the fluid's held rows of 2026-12-07).
Exit 0, or 1 (with a line) if FILE has no block BLOCK."""
import struct
import sys

HEAD = struct.Struct("<8sIIdqQ")  # magic, version, 0, time, number, image bytes


def fnv1a(data):
    h = 14695981039346656037
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def pad8(n):
    return (n + 7) & ~7


def main():
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--only"):
        print(__doc__)
        return 2
    path, keep = sys.argv[1], sys.argv[2]
    only = len(sys.argv) == 4
    with open(path, "rb") as f:
        data = f.read()
    magic, version, zero, time, number, nbytes = HEAD.unpack_from(data)
    image = data[HEAD.size:HEAD.size + nbytes]
    pos = 0
    while pos + 2 <= len(image):
        (nl,) = struct.unpack_from("<H", image, pos)
        name = image[pos + 2:pos + 2 + nl].decode()
        head = pad8(2 + nl)
        (bl,) = struct.unpack_from("<Q", image, pos + head)
        start = pos
        pos += head + 8 + pad8(bl)
        if name == keep:
            image = image[:start] + image[pos:] if only else image[:pos]
            with open(path, "wb") as f:
                f.write(HEAD.pack(magic, version, zero, time, number, len(image)))
                f.write(image)
                f.write(struct.pack("<Q", fnv1a(image)))
            print("ckpt_cut: %s %s block %s (%d bytes of image)"
                  % (path, "without" if only else "cut after", keep, len(image)))
            return 0
    print("ckpt_cut: %s has no block %s" % (path, keep))
    return 1


if __name__ == "__main__":
    sys.exit(main())
