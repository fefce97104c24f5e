# Makefile for libmech and the `mech` command line.
#   make            build build/libmech.a and build/mech (warnings are errors)
#   make deps       install missing Debian packages (apt-get; tools/deps.sh)
#   make run        deps + build + the main job: solve the Stirling engine
#   make test       deps + build + the full test suite
#   make test-san   the test suite built with -fsanitize=address,undefined
#   make test-browser  figures, animation and report rendered by headless chromium
#   make test-slurm    docs/batch.md's Slurm recipes on a single-node Slurm (root)
#   make bench      optimised benchmarks, printed as tables
#   make golden     regenerate tests/golden/*.csv (review the diff by hand)
#   make install PREFIX=/usr/local   mech, libmech.so/.a, mech.h, mech.pc, mech.1,
#                   the Python module mech (docs/api.md; WITH_PYTHON=0 leaves it
#                   out, and with it python3-dev and numpy); DESTDIR is honoured
#   make python     build the Python extension only (build/python/mech)
#   make test-python   pytest on the Python module, installed in a temporary prefix
#   make clean
CC      ?= cc
PREFIX  ?= /usr/local
BUILD   ?= build
OPT     ?= -O2 -g
SAN     ?=
CFLAGS_BASE = -std=c11 -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes \
              -Wmissing-prototypes -Wno-missing-field-initializers -D_POSIX_C_SOURCE=200809L
# SuiteSparse KLU: pkg-config when a .pc exists, else the Debian 12 layout.
KLU_CFLAGS := $(shell pkg-config --cflags klu 2>/dev/null || echo -I/usr/include/suitesparse)
KLU_LIBS   := $(shell pkg-config --libs klu 2>/dev/null || echo -lklu -lbtf -lamd -lcolamd -lsuitesparseconfig)
YAML_CFLAGS := $(shell pkg-config --cflags yaml-0.1 2>/dev/null)
YAML_LIBS   := $(shell pkg-config --libs yaml-0.1 2>/dev/null || echo -lyaml)
CRIT_LIBS   := $(shell pkg-config --libs criterion 2>/dev/null || echo -lcriterion)
# Debian's Python (python3-dev, python3-numpy), not a python3 earlier in PATH
PYTHON      ?= $(shell test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
PY_CFLAGS    = $(shell $(PYTHON)-config --includes 2>/dev/null) \
               -I$(shell $(PYTHON) -c 'import numpy; print(numpy.get_include())' 2>/dev/null)
PY_EXT      := $(shell $(PYTHON)-config --extension-suffix 2>/dev/null || echo .so)
PYDIR        = lib/python3/dist-packages
WITH_PYTHON ?= 1

# The library's version is MECH_VERSION in mech.h; the soname carries its
# first number (the ABI: bumped when a struct or signature changes).
VERSION := $(shell sed -n 's/^\#define MECH_VERSION "\(.*\)"/\1/p' include/mech.h)
SOMAJOR := $(firstword $(subst ., ,$(VERSION)))
SONAME   = libmech.so.$(SOMAJOR)

CFLAGS  = $(CFLAGS_BASE) $(OPT) $(SAN) -Iinclude $(YAML_CFLAGS) $(KLU_CFLAGS)
LDLIBS  = $(YAML_LIBS) $(KLU_LIBS) -lm -pthread
LDFLAGS = $(SAN) -pthread

CMD_SRC  = src/main.c $(wildcard src/cmd_*.c)
CMD_OBJ  = $(CMD_SRC:src/%.c=$(BUILD)/obj/%.o)
LIB_SRC  = $(filter-out $(CMD_SRC),$(wildcard src/*.c))
LIB_OBJ  = $(LIB_SRC:src/%.c=$(BUILD)/pic/%.o)
TEST_SRC = $(wildcard tests/unit/*.c)
TEST_OBJ = $(TEST_SRC:tests/unit/%.c=$(BUILD)/tests/%.o)

.PHONY: all lib python deps run test test-san test-valgrind test-browser test-install test-python test-slurm \
        fuzz fuzz-replay bench golden install clean

all: $(BUILD)/mech lib

lib: $(BUILD)/libmech.a $(BUILD)/libmech.so

HEADERS = include/mech.h $(wildcard src/*.h)

$(BUILD)/obj/%.o: src/%.c $(HEADERS) | $(BUILD)/obj
	$(CC) $(CFLAGS) -c $< -o $@

# Library objects are position independent (their own directory, so a tree
# built before is not mixed in): the same objects make the static library
# and the shared one, which Python's extension (or ctypes) loads.
$(BUILD)/pic/%.o: src/%.c $(HEADERS) | $(BUILD)/pic
	$(CC) $(CFLAGS) -fPIC -c $< -o $@

$(BUILD)/libmech.a: $(LIB_OBJ)
	rm -f $@
	ar rcs $@ $^

# libmech.so -> libmech.so.0 -> libmech.so.0.1.0; only the mech_* names are
# exported (libmech.map), the modules' internal functions stay local.
$(BUILD)/libmech.so.$(VERSION): $(LIB_OBJ) libmech.map
	$(CC) $(LDFLAGS) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=libmech.map \
	    -Wl,--no-undefined -o $@ $(LIB_OBJ) $(LDLIBS)

$(BUILD)/libmech.so: $(BUILD)/libmech.so.$(VERSION)
	ln -sf libmech.so.$(VERSION) $(BUILD)/$(SONAME)
	ln -sf $(SONAME) $@

# The Python extension mech._mech (python/mech_module.c), linked with the
# shared library; its run path finds libmech.so.0 from P/lib/python3/dist-packages/mech.
python: $(BUILD)/python/mech/_mech$(PY_EXT) $(BUILD)/python/mech/__init__.py

$(BUILD)/python/mech/_mech$(PY_EXT): python/mech_module.c include/mech.h $(BUILD)/libmech.so
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_BASE) -Wno-missing-prototypes $(OPT) $(SAN) -fPIC -shared -Iinclude \
	    $(PY_CFLAGS) -o $@ $< -L$(BUILD) -lmech -Wl,-rpath,'$$ORIGIN/../../..'

$(BUILD)/python/mech/__init__.py: python/mech/__init__.py
	@mkdir -p $(@D)
	cp $< $@

$(BUILD)/mech: $(CMD_OBJ) $(BUILD)/libmech.a
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/tests/%.o: tests/unit/%.c $(HEADERS) $(wildcard tests/unit/*.h) | $(BUILD)/tests
	$(CC) $(CFLAGS) -Isrc -c $< -o $@

# test_compare.c also runs the command line of mech compare (cmd_compare.c)
$(BUILD)/unit-tests: $(TEST_OBJ) $(BUILD)/obj/cmd_compare.o $(BUILD)/libmech.a
	$(CC) $(LDFLAGS) -o $@ $^ $(CRIT_LIBS) $(LDLIBS)

# cmd_run_parallel with a pthread_create failing half-way (tests/pool/pool_fail.c
# replaces pthread_create and pthread_join)
$(BUILD)/pool-fail: tests/pool/pool_fail.c $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(LDLIBS)

# the default -j of batch and sweep under a restricted CPU affinity mask
$(BUILD)/affinity: tests/pool/affinity.c $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/obj $(BUILD)/pic $(BUILD)/tests:
	mkdir -p $@

deps:
	@sh tools/deps.sh

# The main job: solve the Stirling engine of the first paper over one crank
# revolution (positions, velocities, accelerations) into build/stirling.csv.
run: deps
	@$(MAKE) --no-print-directory all
	$(BUILD)/mech check -q mechanisms/*.yaml
	$(BUILD)/mech solve mechanisms/stirling.yaml -o $(BUILD)/stirling.csv --stats
	@echo "wrote $(BUILD)/stirling.csv"

test: deps
	@$(MAKE) --no-print-directory $(BUILD)/mech $(BUILD)/unit-tests
	$(BUILD)/unit-tests --jobs 2
	@$(MAKE) --no-print-directory $(BUILD)/pool-fail
	$(BUILD)/pool-fail
	@$(MAKE) --no-print-directory $(BUILD)/affinity
	$(BUILD)/affinity
	MECH=$(BUILD)/mech sh tests/cli.sh
	MECH=$(BUILD)/mech sh tests/cli_compare.sh
	MECH=$(BUILD)/mech sh tests/files.sh
	MECH=$(BUILD)/mech sh tests/golden.sh
	MECH=$(BUILD)/mech MECH_SANITIZE=$(if $(SAN),1,) sh tests/sweep.sh
	MECH=$(BUILD)/mech MECH_SANITIZE=$(if $(SAN),1,) sh tests/sweep_random.sh
	MECH=$(BUILD)/mech MECH_SANITIZE=$(if $(SAN),1,) sh tests/codegen.sh
	MECH=$(BUILD)/mech sh tests/report.sh
	MECH=$(BUILD)/mech sh tests/drivers.sh
	MECH=$(BUILD)/mech sh tests/parallel/recipes.sh
	@$(MAKE) --no-print-directory test-install test-python

# The Slurm recipes of docs/batch.md run as written against a single-node
# Slurm that tests/slurm/recipes.sh starts on localhost and stops (root,
# Debian slurm-wlm and munge).
test-slurm: $(BUILD)/mech
	@sh tools/deps.sh slurm-wlm munge
	MECH=$(BUILD)/mech sh tests/slurm/recipes.sh

# make install into a temporary prefix, then the example of docs/api.md
# built with pkg-config alone (shared and --static), its numbers against
# mech solve's CSV, and the man page rendered.
test-install: lib python $(BUILD)/mech
	BUILD=$(BUILD) CC="$(CC)" OPT="$(OPT)" SAN="$(SAN)" MAKE="$(MAKE)" sh tests/install.sh

# pytest on the Python module installed into a temporary prefix. Under the
# sanitizers the extension and the library are instrumented and python3 is
# not: the sanitizers' run-time libraries are preloaded (leak detection off:
# the interpreter keeps its memory at exit).
SAN_PRELOAD = $(if $(findstring address,$(SAN)),$(shell $(CC) -print-file-name=libasan.so)) \
              $(if $(findstring undefined,$(SAN)),$(shell $(CC) -print-file-name=libubsan.so))
test-python: lib python $(BUILD)/mech
	BUILD=$(BUILD) PYTHON=$(PYTHON) MAKE="$(MAKE)" OPT="$(OPT)" SAN="$(SAN)" \
	    SAN_PRELOAD="$(strip $(if $(SAN),$(SAN_PRELOAD)))" sh tests/python/run.sh

test-san:
	@$(MAKE) --no-print-directory test BUILD=build/san OPT="-O1 -g -fno-omit-frame-pointer" \
	    SAN="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all"

# Fuzzing with clang's libFuzzer (tests/fuzz/README.md): fuzz runs
# FUZZ_SECONDS (default 60); fuzz-replay only the regression inputs.
fuzz:
	FUZZ_BUILD=$(BUILD)/fuzz sh tests/fuzz/run.sh
fuzz-replay:
	FUZZ_BUILD=$(BUILD)/fuzz sh tests/fuzz/run.sh replay

# mech under valgrind on every mechanism: no invalid accesses, no leaks.
test-valgrind: $(BUILD)/mech
	MECH=$(BUILD)/mech sh tests/valgrind.sh

# Figures, animation and the HTML report seen by headless chromium
# (docs/plots.md, docs/report.md).
test-browser: $(BUILD)/mech
	MECH=$(BUILD)/mech OUT=$(BUILD)/browser sh tests/browser/run.sh
	MECH=$(BUILD)/mech OUT=$(BUILD)/browser-report sh tests/browser/report.sh

# Benchmarks: optimised, no sanitizers; prints tables and writes them, with
# the plots, into docs/performance.md (bench/report.sh).
bench:
	@$(MAKE) --no-print-directory BUILD=build/bench OPT="-O2 -DNDEBUG" build/bench/bench-eval \
	    build/bench/bench-solve build/bench/bench-hand build/bench/bench-accuracy build/bench/bench-scale \
	    build/bench/mech build/bench/bench-alloc build/bench/bench-sweep
	{ build/bench/bench-eval mechanisms/*.yaml && \
	  build/bench/bench-solve mechanisms/*.yaml bench/files/*.yaml && \
	  build/bench/bench-hand mechanisms && \
	  MECH=build/bench/mech BUILD=build/bench sh bench/bench_codegen.sh && \
	  sh bench/bench_ratio.sh build/bench/bench-hand && \
	  build/bench/bench-accuracy mechanisms build/bench && \
	  build/bench/bench-scale build/bench && \
	  MECH=build/bench/mech sh bench/bench_batch.sh && \
	  build/bench/bench-sweep mechanisms/conveyor.yaml l1 55 65 && \
	  build/bench/bench-alloc mechanisms/*.yaml; } 2>&1 | tee build/bench/report.txt
	sh bench/report.sh build/bench/report.txt

$(BUILD)/bench-eval: bench/bench_eval.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-solve: bench/bench_solve.c bench/bench_util.h $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-sweep: bench/bench_sweep.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-alloc: bench/bench_alloc.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-hand: bench/bench_hand.c bench/bench_util.h $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

# the high-precision references use GCC's __float128 (libquadmath)
$(BUILD)/bench-accuracy: bench/bench_accuracy.c bench/bench_util.h tests/unit/closed_forms.h \
    $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Itests/unit -o $@ $< $(BUILD)/libmech.a $(LDLIBS) -lquadmath

# dense LU for comparison: LAPACK (liblapack-dev, a dependency of libsuitesparse-dev)
$(BUILD)/bench-scale: bench/bench_scale.c bench/bench_util.h $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -Isrc -o $@ $< $(BUILD)/libmech.a $(LDLIBS) -llapack -lblas

# Regenerate tests/golden/NAME.csv from mechanisms/NAME.yaml. Review the diff
# (git diff --stat tests/golden; mech compare) before committing new goldens.
golden: all
	@for f in mechanisms/*.yaml; do \
	    n=$$(basename $$f .yaml); \
	    echo "$(BUILD)/mech solve $$f -o tests/golden/$$n.csv"; \
	    $(BUILD)/mech solve $$f -o tests/golden/$$n.csv || exit 1; \
	done

install: all $(if $(filter 1,$(WITH_PYTHON)),python)
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig \
	    $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/share/man/man1
	install -m 755 $(BUILD)/mech $(DESTDIR)$(PREFIX)/bin/mech
	install -m 644 $(BUILD)/libmech.a $(DESTDIR)$(PREFIX)/lib/libmech.a
	install -m 755 $(BUILD)/libmech.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/libmech.so.$(VERSION)
	ln -sf libmech.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(PREFIX)/lib/libmech.so
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' -e 's|@KLU_LIBS@|$(KLU_LIBS)|' \
	    mech.pc.in >$(DESTDIR)$(PREFIX)/lib/pkgconfig/mech.pc
	install -m 644 include/mech.h $(DESTDIR)$(PREFIX)/include/mech.h
	install -m 644 docs/mech.1 $(DESTDIR)$(PREFIX)/share/man/man1/mech.1
ifeq ($(WITH_PYTHON),1)
	install -d $(DESTDIR)$(PREFIX)/$(PYDIR)/mech
	install -m 644 python/mech/__init__.py $(DESTDIR)$(PREFIX)/$(PYDIR)/mech/__init__.py
	install -m 755 $(BUILD)/python/mech/_mech$(PY_EXT) $(DESTDIR)$(PREFIX)/$(PYDIR)/mech/_mech$(PY_EXT)
endif

clean:
	rm -rf build
