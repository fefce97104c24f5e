# Makefile for libmech and the `mech` command line.
#   make            build build/libmech.a and build/mech (warnings are errors)
#   make deps       install missing Debian packages (apt-get; tools/deps.sh)
#   make run        deps + build + the main job: solve the Stirling engine
#   make test       deps + build + the full test suite, each suite timed
#   make check      the fast tier (about a minute): the same suites, each
#                   shell suite's fast subset (MECH_QUICK=1; docs/testing.md)
#   make test-san   the test suite built with -fsanitize=address,undefined
#   make test-browser  figures, animation, report and mech watch in headless chromium
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
# MINPACK (libcminpack-dev): mech fit's least squares (src/study/fit_lm.c),
# linked into libmech.so (shared). Debian ships no static libcminpack.a, so
# mech.pc's Libs.private leaves it out: a static link pulls fit_lm.o (and
# needs -lcminpack) only when it calls mech_fit, which api_example does not.
MINPACK_CFLAGS := $(shell pkg-config --cflags cminpack 2>/dev/null || echo -I/usr/include/cminpack-1)
MINPACK_LIBS   := $(shell pkg-config --libs cminpack 2>/dev/null || echo -lcminpack)
# NLopt (libnlopt-dev): the gradient-free minimisers `make bench` compares mech
# fit with (bench/bench_fit.c), in that benchmark only.
NLOPT_CFLAGS := $(shell pkg-config --cflags nlopt 2>/dev/null)
NLOPT_LIBS   := $(shell pkg-config --libs nlopt 2>/dev/null || echo -lnlopt)
# The Python the module is built for: Debian's python3 (python3-dev,
# python3-numpy), not a python3 earlier in PATH, unless PYTHON names another
# (a pyenv or venv python with its own numpy). python/buildinfo.py asks that
# interpreter for its headers, numpy, extension suffix and module directory
# (docs/api.md, "Python").
PYTHON      ?= $(shell test -x /usr/bin/python3 && echo /usr/bin/python3 || echo python3)
PY_INFO      = $(PYTHON) python/buildinfo.py
PY_CFLAGS    = $(shell $(PY_INFO) cflags 2>/dev/null) $(shell $(PY_INFO) defines 2>/dev/null)
PY_EXT      := $(shell $(PY_INFO) suffix 2>/dev/null || echo .so)
PYDIR       ?= $(shell $(PY_INFO) pydir 2>/dev/null || echo lib/python3/dist-packages)
WITH_PYTHON ?= 1

# The library's version is MECH_VERSION in mech.h; the soname carries the
# ABI (docs/api.md, "Versions and the ABI"): libmech.so.0.MINOR before 1.0,
# libmech.so.MAJOR from 1.0. libmech.map names the symbols' version node.
VERSION := $(shell sed -n 's/^\#define MECH_VERSION "\([0-9][0-9.]*\)"$$/\1/p' include/mech.h)
# one word or nothing would name other targets (a path pattern in the
# version was once a target list reaching outside the tree)
ifneq ($(words $(VERSION)),1)
$(error include/mech.h: no '#define MECH_VERSION "MAJOR.MINOR.PATCH"' line alone)
endif
SOMAJOR := $(word 1,$(subst ., ,$(VERSION)))
SOMINOR := $(word 2,$(subst ., ,$(VERSION)))
SOABI    = $(if $(filter 0,$(SOMAJOR)),0.$(SOMINOR),$(SOMAJOR))
SONAME   = libmech.so.$(SOABI)

SRC_INC = $(addprefix -I,$(SRC_DIRS))
CFLAGS  = $(CFLAGS_BASE) $(OPT) $(SAN) -Iinclude $(SRC_INC) $(YAML_CFLAGS) $(KLU_CFLAGS) $(MINPACK_CFLAGS) $(HDF5_CFLAGS) $(GSL_CFLAGS)
# HDF5 (binary output, -o OUT.h5; src/output/output_h5.c): Debian's
# libhdf5-dev, its serial flavour (pkg-config's plain hdf5 may be MPI's)
HDF5_CFLAGS := $(shell pkg-config --cflags hdf5-serial 2>/dev/null || echo -I/usr/include/hdf5/serial)
HDF5_LIBS   := $(shell pkg-config --libs hdf5-serial 2>/dev/null || echo -lhdf5_serial)
# SUNDIALS CVODE (mech simulate, docs/dynamics.md): Debian's libsundials-dev
# GSL (libgsl-dev): the periodic cubic splines and the one-dimensional
# minimiser and root finder of a cam given by its profile's points
# (src/load/cam_points.c, docs/cams.md 7)
GSL_CFLAGS := $(shell pkg-config --cflags gsl 2>/dev/null)
GSL_LIBS   := $(shell pkg-config --libs gsl 2>/dev/null || echo -lgsl -lgslcblas)
SUNDIALS_LIBS = -lsundials_cvode -lsundials_sunlinsoldense -lsundials_sunmatrixdense \
                -lsundials_nvecserial -lsundials_generic
LDLIBS  = $(YAML_LIBS) $(KLU_LIBS) $(SUNDIALS_LIBS) $(HDF5_LIBS) $(MINPACK_LIBS) $(GSL_LIBS) -lm -pthread
LDFLAGS = $(SAN) -pthread

# src/ is one folder per stage of the pipeline, each with one header
# (docs/architecture.md, "Stages"): a stage uses only those before it in
# STAGES (tools/stages.py checks the objects' symbols). runtime/ is the C
# that libmech and the generated code share.
STAGES   = runtime base symbolic load equations solve forces study output codegen cli
SRC_DIRS = $(addprefix src/,$(STAGES))
vpath %.c $(SRC_DIRS)
CMD_SRC  = $(wildcard src/cli/*.c)
CMD_OBJ  = $(patsubst %.c,$(BUILD)/obj/%.o,$(notdir $(CMD_SRC)))
LIB_SRC  = $(filter-out $(CMD_SRC),$(wildcard src/*/*.c))
LIB_OBJ  = $(patsubst %.c,$(BUILD)/pic/%.o,$(notdir $(LIB_SRC))) $(BUILD)/pic/rt_text.o
# The runtime libmech and the generated code share (docs/codegen.md): real C,
# compiled into libmech through its includers, and its text carried by `mech
# codegen` (build/gen/rt_text.c, in the order the generated source needs it).
RT_SRC   = $(addprefix src/runtime/,rt_base.h rt_blocklu.h rt_newton.h rt_frame.h rt_forces.h rt_law.h rt_solver.h)
TEST_SRC = $(wildcard tests/unit/*.c)
TEST_OBJ = $(TEST_SRC:tests/unit/%.c=$(BUILD)/tests/%.o)

.PHONY: all lib python deps run test check test-san test-valgrind test-browser test-install test-python test-slurm \
        fuzz fuzz-replay bench golden install clean

all: $(BUILD)/mech lib

lib: $(BUILD)/libmech.a $(BUILD)/libmech.so

HEADERS = include/mech.h $(wildcard src/*/*.h)

$(BUILD)/obj/%.o: %.c $(HEADERS) | $(BUILD)/obj
	$(CC) $(CFLAGS) -c $< -o $@

# Library objects are position independent (their own directory, so a tree
# built before is not mixed in): the same objects make the static library
# and the shared one, which Python's extension (or ctypes) loads.
$(BUILD)/pic/%.o: %.c $(HEADERS) | $(BUILD)/pic
	$(CC) $(CFLAGS) -fPIC -c $< -o $@

# The runtime's text as C arrays of lines (codegen_rt_NAME[]) for the generator.
$(BUILD)/gen/rt_text.c: $(RT_SRC) tools/c_lines.awk | $(BUILD)/gen
	awk -f tools/c_lines.awk $(RT_SRC) >$@.tmp && mv $@.tmp $@

$(BUILD)/pic/rt_text.o: $(BUILD)/gen/rt_text.c $(HEADERS) | $(BUILD)/pic
	$(CC) $(CFLAGS) -fPIC -c $< -o $@

$(BUILD)/libmech.a: $(LIB_OBJ)
	rm -f $@
	ar rcs $@ $^

# libmech.so -> libmech.so.0.2 -> libmech.so.0.2.0; only the mech_* names are
# exported (libmech.map, version node MECH_0.2), the modules' internal
# functions stay local.
$(BUILD)/libmech.so.$(VERSION): $(LIB_OBJ) libmech.map
	$(CC) $(LDFLAGS) -shared -Wl,-soname,$(SONAME) -Wl,--version-script=libmech.map \
	    -Wl,--no-undefined -o $@ $(LIB_OBJ) $(LDLIBS)

$(BUILD)/libmech.so: $(BUILD)/libmech.so.$(VERSION)
	ln -sf libmech.so.$(VERSION) $(BUILD)/$(SONAME)
	ln -sf $(SONAME) $@

# The Python extension mech._mech (python/mech_module.c), linked with the
# shared library; its run path finds $(SONAME) from P/lib/python3/dist-packages/mech.
python: $(BUILD)/python/mech/_mech$(PY_EXT) $(BUILD)/python/mech/__init__.py

# What the extension is built for (PYTHON, its version and numpy's): the
# file changes when they do, and the extension is built again; the build
# stops here, saying why, when PYTHON cannot build it (no numpy, no headers).
$(BUILD)/python/built-for: FORCE
	@mkdir -p $(@D)
	@$(PY_INFO) check >$@.new || { rm -f $@.new; exit 1; }
	@if cmp -s $@.new $@; then rm -f $@.new; else mv $@.new $@; fi

FORCE:

$(BUILD)/python/mech/_mech$(PY_EXT): python/mech_module.c include/mech.h $(BUILD)/libmech.so \
    $(BUILD)/python/built-for
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_BASE) -Wno-missing-prototypes $(OPT) $(SAN) -fPIC -shared -Iinclude \
	    $(PY_CFLAGS) -o $@ $< -L$(BUILD) -lmech -Wl,-rpath,'$$ORIGIN/../../..'

$(BUILD)/python/mech/__init__.py: python/mech/__init__.py
	@mkdir -p $(@D)
	cp $< $@

$(BUILD)/mech: $(CMD_OBJ) $(BUILD)/libmech.a
	$(CC) $(LDFLAGS) -o $@ $^ $(MINPACK_LIBS) $(LDLIBS)

$(BUILD)/tests/%.o: tests/unit/%.c $(HEADERS) $(wildcard tests/unit/*.h) | $(BUILD)/tests
	$(CC) $(CFLAGS) -c $< -o $@

# test_compare.c also runs the command line of mech compare (cmd_compare.c),
# test_cmd_opts.c the option parser (cmd_opts.c) and every command's table,
# test_rowcheck.c the row checks (cmd_rowcheck.c) and digests (cmd_manifest.c)
# test_http.c the request parser of mech watch (cmd_http.c)
CMD_TESTED = $(filter-out $(BUILD)/obj/main.o,$(CMD_OBJ))
$(BUILD)/unit-tests: $(TEST_OBJ) $(CMD_TESTED) $(BUILD)/libmech.a
	$(CC) $(LDFLAGS) -o $@ $^ $(CRIT_LIBS) $(MINPACK_LIBS) $(LDLIBS)

# parallel_run with a pthread_create failing half-way (tests/pool/pool_fail.c
# replaces pthread_create and pthread_join)
$(BUILD)/pool-fail: tests/pool/pool_fail.c $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(LDLIBS)

# the default -j of batch and sweep under a restricted CPU affinity mask
$(BUILD)/affinity: tests/pool/affinity.c $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/obj/cmd_common.o $(BUILD)/libmech.a $(LDLIBS)

# a command run with known signal dispositions (tests/lib.sh, tests/signals.sh)
$(BUILD)/sigexec: tests/sigexec.c | $(BUILD)/obj
	$(CC) $(CFLAGS) -o $@ $<

$(BUILD)/obj $(BUILD)/pic $(BUILD)/tests $(BUILD)/gen:
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

# SUITES: what make test runs in full and make check (QUICK=1) in its fast
# subset: the unit tests but UNIT_SLOW, each shell suite under MECH_QUICK=1
# (docs/testing.md). A line per suite (a new suite is one more line), each
# timed by tests/timed.sh: "time: NAME ..." when it ends, a table at the end.
# UNIT_SLOW: the longest unit tests (a chain of 100 000 four-bars, every
# parameter of every mechanism swept, ...: two thirds of the unit tests' time)
UNIT_SLOW = limits/chain_of_100000_fourbars sweep_shared/every_parameter_of_every_mechanism \
            limits/one_pin_on_many_links hard/chain_10000_solves_in_linear_time \
            sensitivity/stackup_bounds_a_monte_carlo_sweep_of_10000_samples
space    := $() $()
TEST_BIN  = $(BUILD)/mech $(BUILD)/unit-tests $(BUILD)/pool-fail $(BUILD)/affinity $(BUILD)/sigexec
TIMED     = sh tests/timed.sh $(BUILD)/$@-times.txt
SUITE_ENV = env MECH=$(BUILD)/mech MECH_QUICK=$(QUICK)
SAN_ENV   = MECH_SANITIZE=$(if $(SAN),1,)
define SUITES
	@$(MAKE) --no-print-directory $(TEST_BIN)
	@$(TIMED) begin
	$(TIMED) stages python3 tools/stages.py $(BUILD)
	$(TIMED) unit $(BUILD)/unit-tests --jobs 2 $(if $(QUICK),--filter '!($(subst $(space),|,$(strip $(UNIT_SLOW))))')
	$(TIMED) pool-fail $(BUILD)/pool-fail
	$(TIMED) affinity $(BUILD)/affinity
	$(TIMED) cli $(SUITE_ENV) sh tests/cli.sh
	$(TIMED) cli_compare $(SUITE_ENV) sh tests/cli_compare.sh
	$(TIMED) files $(SUITE_ENV) sh tests/files.sh
	$(TIMED) signals $(SUITE_ENV) sh tests/signals.sh
	$(TIMED) golden $(SUITE_ENV) sh tests/golden.sh
	$(TIMED) rcond $(SUITE_ENV) sh tests/rcond.sh
	$(TIMED) sweep $(SUITE_ENV) $(SAN_ENV) sh tests/sweep.sh
	$(TIMED) sweep_random $(SUITE_ENV) $(SAN_ENV) sh tests/sweep_random.sh
	$(TIMED) merge $(SUITE_ENV) $(SAN_ENV) sh tests/merge.sh
	$(TIMED) codegen $(SUITE_ENV) $(SAN_ENV) sh tests/codegen.sh
	$(TIMED) jit $(SUITE_ENV) sh tests/jit.sh
	$(TIMED) report $(SUITE_ENV) sh tests/report.sh
	$(TIMED) draw $(SUITE_ENV) sh tests/draw.sh
	$(TIMED) watch $(SUITE_ENV) sh tests/watch.sh
	$(TIMED) drivers $(SUITE_ENV) sh tests/drivers.sh
	$(TIMED) programs $(SUITE_ENV) sh tests/programs.sh
	$(TIMED) cams $(SUITE_ENV) sh tests/cams.sh
	$(TIMED) cam_points $(SUITE_ENV) sh tests/cam_points.sh
	$(TIMED) fit $(SUITE_ENV) sh tests/fit.sh
	$(TIMED) dynamics $(SUITE_ENV) sh tests/dynamics.sh
	$(TIMED) drawn $(SUITE_ENV) sh tests/drawn.sh
	$(TIMED) warn $(SUITE_ENV) sh tests/warn.sh
	$(TIMED) parallel $(SUITE_ENV) sh tests/parallel/recipes.sh
	$(TIMED) install $(MAKE) --no-print-directory test-install
	$(TIMED) python $(MAKE) --no-print-directory test-python QUICK=$(QUICK)
	@$(TIMED) table
endef

test: deps
	$(SUITES)

# The fast tier, between edits: the same suites, each shell suite's fast
# subset (about a minute on two cores, built; docs/testing.md).
check: QUICK = 1
check:
	$(SUITES)

# The Slurm recipes of docs/batch.md run as written against a single-node
# Slurm that tests/slurm/recipes.sh starts on localhost and stops (root,
# Debian slurm-wlm and munge).
test-slurm: $(BUILD)/mech
	@sh tools/deps.sh slurm-wlm munge
	MECH=$(BUILD)/mech sh tests/slurm/recipes.sh

# The C API's contract through the shared library (tests/api.sh: NULL
# arguments, the options' size, the soname and version node); make install
# into a temporary prefix, then the example of docs/api.md built with
# pkg-config alone (shared and --static), its numbers against mech solve's
# CSV, and the man page rendered.
test-install: lib python $(BUILD)/mech
	BUILD=$(BUILD) CC="$(CC)" SAN="$(SAN)" sh tests/api.sh
	BUILD=$(BUILD) CC="$(CC)" OPT="$(OPT)" SAN="$(SAN)" MAKE="$(MAKE)" sh tests/install.sh

# pytest on the Python module installed into a temporary prefix, then the
# module built for other interpreters (tests/python/interpreters.sh: not in
# make check's quick tier, and not under the sanitizers, whose run-time the
# other interpreters would lack). Under the sanitizers the extension and the
# library are instrumented and python3 is not: the sanitizers' run-time
# libraries are preloaded (leak detection off: the interpreter keeps its
# memory at exit).
SAN_PRELOAD = $(if $(findstring address,$(SAN)),$(shell $(CC) -print-file-name=libasan.so)) \
              $(if $(findstring undefined,$(SAN)),$(shell $(CC) -print-file-name=libubsan.so))
test-python: lib python $(BUILD)/mech
	BUILD=$(BUILD) PYTHON=$(PYTHON) MAKE="$(MAKE)" OPT="$(OPT)" SAN="$(SAN)" \
	    SAN_PRELOAD="$(strip $(if $(SAN),$(SAN_PRELOAD)))" sh tests/python/run.sh
	$(if $(SAN)$(QUICK),,BUILD=$(BUILD) PYTHON=$(PYTHON) MAKE="$(MAKE)" OPT="$(OPT)" \
	    sh tests/python/interpreters.sh)

test-san:
	@$(MAKE) --no-print-directory test BUILD=build/san OPT="-O1 -g -fno-omit-frame-pointer" \
	    SAN="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=all"

# Fuzzing with clang's libFuzzer (tests/fuzz/README.md): fuzz runs
# FUZZ_SECONDS (default 60); fuzz-replay only the regression inputs.
fuzz:
	FUZZ_BUILD=$(BUILD)/fuzz FUZZ_CFLAGS="$(HDF5_CFLAGS) $(MINPACK_CFLAGS) $(GSL_CFLAGS)" FUZZ_LIBS="$(SUNDIALS_LIBS) $(HDF5_LIBS) $(MINPACK_LIBS) $(GSL_LIBS)" sh tests/fuzz/run.sh
fuzz-replay:
	FUZZ_BUILD=$(BUILD)/fuzz FUZZ_CFLAGS="$(HDF5_CFLAGS) $(MINPACK_CFLAGS) $(GSL_CFLAGS)" FUZZ_LIBS="$(SUNDIALS_LIBS) $(HDF5_LIBS) $(MINPACK_LIBS) $(GSL_LIBS)" sh tests/fuzz/run.sh replay

# mech under valgrind on every mechanism: no invalid accesses, no leaks.
test-valgrind: $(BUILD)/mech
	MECH=$(BUILD)/mech sh tests/valgrind.sh

# Figures, animation, the HTML report and mech watch's live page seen by
# headless chromium (docs/plots.md, docs/report.md, docs/cli.md).
test-browser: $(BUILD)/mech
	MECH=$(BUILD)/mech OUT=$(BUILD)/browser sh tests/browser/run.sh
	MECH=$(BUILD)/mech OUT=$(BUILD)/browser-report sh tests/browser/report.sh
	MECH=$(BUILD)/mech OUT=$(BUILD)/browser-watch sh tests/browser/watch.sh

# Benchmarks: optimised, no sanitizers; prints tables and writes them, with
# the plots, into docs/performance.md (bench/report.sh).
bench:
	@$(MAKE) --no-print-directory BUILD=build/bench OPT="-O2 -DNDEBUG" build/bench/bench-eval \
	    build/bench/bench-solve build/bench/bench-hand build/bench/bench-accuracy build/bench/bench-scale \
	    build/bench/mech build/bench/bench-alloc build/bench/bench-sweep build/bench/bench-fit
	{ build/bench/bench-eval mechanisms/*.yaml && \
	  build/bench/bench-solve mechanisms/*.yaml bench/files/*.yaml && \
	  build/bench/bench-hand mechanisms && \
	  MECH=build/bench/mech BUILD=build/bench sh bench/bench_codegen.sh && \
	  MECH=build/bench/mech sh bench/bench_compile.sh && \
	  sh bench/bench_ratio.sh build/bench/bench-hand && \
	  build/bench/bench-accuracy mechanisms build/bench && \
	  build/bench/bench-scale build/bench && \
	  MECH=build/bench/mech sh bench/bench_batch.sh && \
	  MECH=build/bench/mech sh bench/bench_simulate.sh && \
	  MECH=build/bench/mech sh bench/bench_output.sh && \
	  build/bench/bench-sweep mechanisms/conveyor.yaml l1 55 65 && \
	  build/bench/bench-fit tests/fit/fourbar.yaml && \
	  build/bench/bench-alloc mechanisms/*.yaml; } 2>&1 | tee build/bench/report.txt
	sh bench/report.sh build/bench/report.txt

$(BUILD)/bench-eval: bench/bench_eval.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-solve: bench/bench_solve.c bench/bench_util.h $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

$(BUILD)/bench-sweep: bench/bench_sweep.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS)

# mech fit's lmder (src/study/fit_lm.c, MINPACK) against NLopt's gradient-free methods
$(BUILD)/bench-fit: bench/bench_fit.c $(BUILD)/libmech.a $(HEADERS)
	$(CC) $(CFLAGS) $(NLOPT_CFLAGS) -o $@ $< $(BUILD)/libmech.a \
	    $(MINPACK_LIBS) $(NLOPT_LIBS) $(LDLIBS)

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
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/libmech.a $(LDLIBS) -llapack -lblas

# Regenerate tests/golden/NAME.csv from mechanisms/NAME.yaml. Review the diff
# (git diff --stat tests/golden; mech compare) before committing new goldens.
golden: all
	@for f in mechanisms/*.yaml; do \
	    n=$$(basename $$f .yaml); \
	    echo "$(BUILD)/mech solve $$f -o tests/golden/$$n.csv"; \
	    $(BUILD)/mech solve $$f -o tests/golden/$$n.csv || exit 1; \
	done
	@for f in mechanisms/cams/*.yaml; do \
	    n=$$(basename $$f .yaml); \
	    echo "$(BUILD)/mech solve $$f -o tests/golden/cams/$$n.csv; mech cam $$f -o tests/golden/cams/$$n.profile.csv"; \
	    $(BUILD)/mech solve $$f -o tests/golden/cams/$$n.csv || exit 1; \
	    $(BUILD)/mech cam $$f -o tests/golden/cams/$$n.profile.csv >/dev/null || exit 1; \
	done
	@for f in mechanisms/dynamics/*.yaml; do \
	    n=$$(basename $$f .yaml); \
	    echo "$(BUILD)/mech simulate $$f --rtol 1e-12 --atol 1e-14 -o tests/golden/dynamics/$$n.csv"; \
	    $(BUILD)/mech simulate $$f --rtol 1e-12 --atol 1e-14 -o tests/golden/dynamics/$$n.csv || exit 1; \
	done

install: all $(if $(filter 1,$(WITH_PYTHON)),python)
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig \
	    $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/share/man/man1
	install -m 755 $(BUILD)/mech $(DESTDIR)$(PREFIX)/bin/mech
	install -m 644 $(BUILD)/libmech.a $(DESTDIR)$(PREFIX)/lib/libmech.a
	install -m 755 $(BUILD)/libmech.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/libmech.so.$(VERSION)
	ln -sf libmech.so.$(VERSION) $(DESTDIR)$(PREFIX)/lib/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(PREFIX)/lib/libmech.so
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(VERSION)|' -e 's|@KLU_LIBS@|$(KLU_LIBS) $(SUNDIALS_LIBS) $(HDF5_LIBS) $(GSL_LIBS)|' \
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
