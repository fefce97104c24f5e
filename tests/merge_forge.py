"""tests/merge_forge.py: what tests/merge.sh needs that a shell cannot do.

  redigest FILE   recompute FILE's '# mech-digest' line (a shard) or its
                  '# mech-block' lines (an OUT.partial): a forger who knows
                  the digest (FNV-1a 64, docs/batch.md), so that the row
                  checks of mech merge and --resume are tested on their own
  gen DIR M A B VERSION
                  write the M shards DIR/s.K.csv of a sweep of A x B variants
                  (--vary a=0:1:A --vary b=0:1:B, bare numbers) as mech sweep
                  --shard K/M would (manifest, grid hash, rows in index
                  order, digest line), with made-up metrics: rows for
                  measuring mech merge without solving 10^7 variants
"""
import os
import sys

FNV0 = 0xcbf29ce484222325
PRIME = 0x100000001b3
MASK = (1 << 64) - 1


def fnv(h, data):
    for b in data:
        h = ((h ^ b) * PRIME) & MASK
    return h


def line_hash(h, line):
    return fnv(h, line + b"\n")


def lines_of(path):
    with open(path, "rb") as f:
        return [l[:-1] if l.endswith(b"\r") else l for l in f.read().split(b"\n")[:-1]]


def redigest(path):
    lines = lines_of(path)
    out, partial = [], path.endswith(".partial")
    head = FNV0
    for l in lines[:2]:
        head = line_hash(head, l)
    h, block = FNV0, head
    rows = nblock = 0
    for i, l in enumerate(lines):
        if l.startswith(b"# mech-digest "):
            out.append(b"# mech-digest rows=%d fnv1a64=%016x" % (rows, h))
            continue
        if l.startswith(b"# mech-block "):
            out.append(b"# mech-block rows=%d fnv1a64=%016x" % (nblock, block))
            block, nblock = head, 0
            continue
        out.append(l)
        h = line_hash(h, l)
        if i >= 2:
            rows += not l.startswith(b"#")
            nblock += 1
            block = line_hash(block, l)
    with open(path, "wb") as f:
        f.write(b"".join(l + b"\n" for l in out))


def shortest(x):
    for p in range(1, 18):
        s = "%.*g" % (p, x)
        if float(s) == x:
            return s
    return s


def gen(d, m, a, b, version):
    texts = []
    for name, n in (("a", a), ("b", b)):
        texts.append((name, ["%.15g" % (0.0 + (1.0 - 0.0) * i / (n - 1)) for i in range(n)]))
    grid = FNV0
    for name, values in texts:
        grid = fnv(grid, name.encode() + b"\0")
        for t in values:
            grid = fnv(grid, t.encode() + b"\0")
    sa = [shortest(float(t)) for t in texts[0][1]]
    sb = [shortest(float(t)) for t in texts[1][1]]
    total = a * b
    header = b"variant [-],a [-],b [-],status [-],rows [-],range:x [m]"
    for k in range(m):
        rows = (total - k + m - 1) // m if total > k else 0
        man = ("# mech-manifest version=%s command=sweep shard=%d/%d rows=%d total=%d offset=0 "
               "input=0123456789abcdef grid=%016x tol=- args=--vary a=0:1:%d --vary b=0:1:%d "
               "--metric range:x" % (version, k, m, rows, total, grid, a, b)).encode()
        h = line_hash(line_hash(FNV0, man), header)
        with open(os.path.join(d, "s.%d.csv" % k), "wb") as f:
            f.write(man + b"\n" + header + b"\n")
            for v in range(k, total, m):
                row = ("%d,%s,%s,ok,361,%.17g" % (v, sa[v // b], sb[v % b], 0.01 + v * 1e-9)).encode()
                h = line_hash(h, row)
                f.write(row + b"\n")
            f.write(b"# mech-digest rows=%d fnv1a64=%016x\n" % (rows, h))


if __name__ == "__main__":
    if sys.argv[1] == "redigest":
        redigest(sys.argv[2])
    elif sys.argv[1] == "gen":
        gen(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), sys.argv[6])
    else:
        sys.exit("usage: merge_forge.py redigest FILE | gen DIR M A B VERSION")
