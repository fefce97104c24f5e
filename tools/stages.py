#!/usr/bin/env python3
"""tools/stages.py BUILD: src/'s stages use only the stages before them.

The stages are the folders of src/, in the order of the Makefile's STAGES
(docs/architecture.md, "Stages"). Two checks, both from what the compiler
and the linker see rather than from a list kept by hand:
  - symbols: every undefined symbol of an object (nm) that another object of
    the tree defines must be defined in the object's own stage or an earlier
    one;
  - headers: a stage's one header (src/S/S.h) and its sources include only
    headers of their own stage or of earlier ones (the runtime's rt_*.h are
    the first stage).
Prints each edge that goes backwards, with the symbols or the include that
make it, and exits 1; exits 0 and prints one line when there is none."""
import glob
import os
import re
import subprocess
import sys


def stages_of_makefile():
    with open('Makefile') as f:
        m = re.search(r'^STAGES\s*=\s*(.*)$', f.read(), re.M)
    if not m:
        sys.exit('stages.py: no STAGES line in the Makefile')
    return m.group(1).split()


def object_stages(stages):
    """basename of each source -> its stage (the folder it is in)."""
    where = {}
    for s in stages:
        for c in glob.glob(os.path.join('src', s, '*.c')):
            where[os.path.basename(c)[:-2]] = s
    where['rt_text'] = 'codegen'  # build/gen/rt_text.c: the runtime's text, for codegen
    return where


def symbols(path):
    out = subprocess.run(['nm', path], capture_output=True, text=True, check=True).stdout
    defined, undefined = set(), set()
    for line in out.splitlines():
        p = line.split()
        if len(p) == 3 and p[1] in 'TDBRV':
            defined.add(p[2])
        elif len(p) == 2 and p[0] == 'U':
            undefined.add(p[1])
    return defined, undefined


def symbol_edges(build, stages, where):
    rank = {s: i for i, s in enumerate(stages)}
    objects = {}
    for d in ('pic', 'obj'):
        for o in glob.glob(os.path.join(build, d, '*.o')):
            name = os.path.basename(o)[:-2]
            if name in where:
                objects[name] = symbols(o)
    if not objects:
        sys.exit('stages.py: no objects under %s/pic or %s/obj: build first' % (build, build))
    definer = {sym: n for n, (defined, _) in objects.items() for sym in defined}
    bad = {}
    for n, (_, undefined) in objects.items():
        for sym in undefined:
            m = definer.get(sym)
            if m and rank[where[m]] > rank[where[n]]:
                bad.setdefault((where[n], where[m]), []).append('%s -> %s: %s' % (n, m, sym))
    return bad


def include_edges(stages):
    rank = {s: i for i, s in enumerate(stages)}
    header_stage = {}
    for s in stages:
        for h in glob.glob(os.path.join('src', s, '*.h')):
            header_stage[os.path.basename(h)] = s
    bad = {}
    for s in stages:
        for f in glob.glob(os.path.join('src', s, '*.[ch]')):
            with open(f) as src:
                for name in re.findall(r'^#include "([^"]+)"', src.read(), re.M):
                    t = header_stage.get(name)
                    if t and rank[t] > rank[s]:
                        bad.setdefault((s, t), []).append('%s includes %s' % (f, name))
    return bad


def main():
    if len(sys.argv) != 2:
        sys.exit('usage: tools/stages.py BUILD_DIR')
    stages = stages_of_makefile()
    where = object_stages(stages)
    bad = symbol_edges(sys.argv[1], stages, where)
    for edge, why in include_edges(stages).items():
        bad.setdefault(edge, []).extend(why)
    for (a, b), why in sorted(bad.items()):
        print('stages: %s uses %s, a later stage (STAGES: %s):' % (a, b, ' '.join(stages)))
        for w in sorted(why)[:8]:
            print('    ' + w)
        if len(why) > 8:
            print('    ... %d more' % (len(why) - 8))
    if bad:
        return 1
    print('stages: %d stages, each uses only those before it: %s'
          % (len(stages), ' -> '.join(stages)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
