# SPDX-License-Identifier: MIT
# foldest: foldable estimators.
#
# The two commands a new user needs are `make demo` and `make check`; both
# install missing Debian packages first (the `deps` step).  Everything is
# discovered from the tree: literate/*.org tangle into include/ and src/,
# src/*.c build the library, src/cli/*.c the `foldest` tool, tests/check_*.c
# the Check suites, examples/*.c and bench/*.c one program each.

VERSION      := 0.1.0
SOVERSION    := 0
PREFIX       ?= /usr/local
DESTDIR      ?=
LIBDIR       ?= $(PREFIX)/lib
INCLUDEDIR   ?= $(PREFIX)/include
BINDIR       ?= $(PREFIX)/bin
MANDIR       ?= $(PREFIX)/share/man
COMPLETIONDIR ?= $(PREFIX)/share/bash-completion/completions

CC           ?= cc
CFLAGS       ?= -O2 -g
WARN         := -std=c11 -Wall -Wextra -Werror -pedantic
CXX          ?= g++
CXXWARN      := -std=c++17 -Wall -Wextra -Werror -pedantic
SAN          := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
TSAN         := -fsanitize=thread -fno-omit-frame-pointer
B            := build

# pkg-config is read when a recipe runs (after `deps`), hence `=` not `:=`.
EXT_CFLAGS    = $(shell pkg-config --cflags lapacke blas)
EXT_LIBS      = $(shell pkg-config --libs lapacke blas) -lm -pthread
BENCH_LIBS    = $(shell pkg-config --libs gsl)
CHECK_CFLAGS  = $(shell pkg-config --cflags check)
# The special functions' tests integrate densities in __float128 (libquadmath).
CHECK_LIBS    = $(shell pkg-config --libs check) -lquadmath
# The command (never the library) reads gzip-compressed tables with zlib.
CLI_LIBS     := -lz

ORG          := $(wildcard literate/*.org)
LIB_SRC      := $(wildcard src/*.c)
CLI_SRC      := $(wildcard src/cli/*.c)
HEADERS      := include/foldest.h $(wildcard include/foldest/*.h)
PRIV_HEADERS := $(wildcard src/*.h)
TEST_SRC     := $(wildcard tests/check_*.c)
EXAMPLES     := $(patsubst examples/%.c,$(B)/examples/%,$(wildcard examples/*.c))
BENCHES      := $(patsubst bench/%.c,$(B)/bench/%,$(wildcard bench/*.c))

LIB_OBJ      := $(patsubst src/%.c,$(B)/obj/%.o,$(LIB_SRC))
SAN_OBJ      := $(patsubst src/%.c,$(B)/san/%.o,$(LIB_SRC))
TSAN_OBJ     := $(patsubst src/%.c,$(B)/tsan/%.o,$(LIB_SRC))
CLI_OBJ      := $(patsubst src/cli/%.c,$(B)/obj/cli/%.o,$(CLI_SRC))
STATIC       := $(B)/lib/libfoldest.a
SHARED       := $(B)/lib/libfoldest.so.$(VERSION)
CLI          := $(B)/bin/foldest

# Real recordings live beside the checkout; tests skip visibly without them.
export FOLDEST_DATA ?= $(abspath ../shared/data)
# One BLAS thread: the matrices are small and valgrind stays quiet.
export OPENBLAS_NUM_THREADS := 1

.PHONY: all deps lib cli examples tests check check-plain check-san check-valgrind \
        check-install check-tangle tangle doc figures check-doc demo run-examples bench size install uninstall clean \
        check-tsan check-mpi bench-mpi lint fuzz fuzz-build coverage accept accept-dynamics mutate audit

all: lib cli examples

# ---------------------------------------------------------------- deps
# A stamp records that the packages were present; .ci/deps does the work.
deps: $(B)/.deps
$(B)/.deps: .ci/deps
	@sh .ci/deps
	@mkdir -p $(B) && touch $@

# ---------------------------------------------------------------- library
lib: $(STATIC) $(SHARED)

$(B)/obj/%.o: src/%.c $(HEADERS) $(PRIV_HEADERS) $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) -fPIC -Iinclude $(EXT_CFLAGS) -c $< -o $@

$(STATIC): $(LIB_OBJ)
	@mkdir -p $(@D)
	rm -f $@ && ar rcs $@ $^

# The shared library exports the public fe_ names and nothing else (a
# version script: no fe__ helper, no compiler-made symbol such as Clang's
# ifunc resolvers, leaks into users' link namespace).
$(SHARED): $(LIB_OBJ)
	@mkdir -p $(@D)
	@printf '{\n  global: fe_[a-z]*;\n  local: *;\n};\n' > $(B)/lib/libfoldest.map
	$(CC) -shared -Wl,-soname,libfoldest.so.$(SOVERSION) -Wl,--version-script=$(B)/lib/libfoldest.map \
	  -o $@ $(LIB_OBJ) $(EXT_LIBS)
	ln -sf libfoldest.so.$(VERSION) $(B)/lib/libfoldest.so.$(SOVERSION)
	ln -sf libfoldest.so.$(VERSION) $(B)/lib/libfoldest.so

# ---------------------------------------------------------------- command line
cli: $(CLI)
$(B)/obj/cli/%.o: src/cli/%.c $(HEADERS) $(wildcard src/cli/*.h) $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) -Iinclude -Isrc/cli -c $< -o $@
$(CLI): $(CLI_OBJ) $(STATIC)
	@mkdir -p $(@D)
	$(if $(CLI_OBJ),$(CC) $(CFLAGS) $(LDFLAGS) -o $@ $(CLI_OBJ) $(STATIC) $(EXT_LIBS) $(CLI_LIBS),@true)

# ---------------------------------------------------------------- examples, bench
examples: $(EXAMPLES)
$(B)/examples/%: examples/%.c $(STATIC)
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) -Iinclude -o $@ $< $(STATIC) $(EXT_LIBS)

$(B)/bench/%: bench/%.c $(STATIC) $(wildcard bench/*.h)
	@mkdir -p $(@D)
	$(CC) $(WARN) -D_POSIX_C_SOURCE=200809L -O3 -march=native -g -Iinclude -Ibench $(EXT_CFLAGS) -o $@ $< $(STATIC) $(EXT_LIBS) $(BENCH_LIBS)

bench: $(BENCHES) $(CLI)
	@for b in $(BENCHES); do echo "== $$b"; FOLDEST=$(abspath $(CLI)) $$b || exit 1; done

# ---------------------------------------------------------------- MPI (optional)
# Only these targets need Open MPI (mpicc, mpirun); libfoldest never links
# it.  examples/mpi/*.c and bench/mpi/*.c include <foldest/mpi.h>; they are
# outside the examples/*.c and bench/*.c wildcards on purpose.
MPICC        ?= mpicc
MPI_NP       ?= 2
MPIRUN        = mpirun -np $(MPI_NP) --oversubscribe $(if $(filter 0,$(shell id -u)),--allow-run-as-root)
MPI_PROGS    := $(patsubst examples/mpi/%.c,$(B)/mpi/%,$(wildcard examples/mpi/*.c))

$(B)/mpi/%: examples/mpi/%.c $(wildcard examples/mpi/*.h) include/foldest/mpi.h $(STATIC)
	@mkdir -p $(@D)
	$(MPICC) $(WARN) $(CFLAGS) -Iinclude -o $@ $< $(STATIC) $(EXT_LIBS)

$(B)/mpi-bench/%: bench/mpi/%.c include/foldest/mpi.h bench/bench.h $(STATIC)
	@mkdir -p $(@D)
	$(MPICC) $(WARN) -D_POSIX_C_SOURCE=200809L -O3 -march=native -g -Iinclude -Ibench -o $@ $< $(STATIC) $(EXT_LIBS)

check-mpi: $(MPI_PROGS)
	@echo "== MPI examples on $(MPI_NP) ranks (each checks itself against the serial fold)"
	sh examples/mpi/check.sh $(B) "$(MPIRUN)"

bench-mpi: $(patsubst bench/mpi/%.c,$(B)/mpi-bench/%,$(wildcard bench/mpi/*.c))
	@for b in $^; do echo "== $$b"; OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 $(MPIRUN) $$b || exit 1; done

# ---------------------------------------------------------------- embedded
# The moment step (src/quadric.c) is freestanding: build it for a Cortex-M4,
# alone and linked into a program that only steps (with libgcc's soft
# double), and report the code size and the size of its state.  Then the
# single-precision step for a Cortex-M4F (hardware float): linked alone, its
# flash (everything the linker keeps) and its state must stay within
# F32_FLASH and F32_STATE bytes (issue 15), with no soft-double routine.
ARM   := arm-none-eabi
ARMCC  = $(ARM)-gcc -mcpu=cortex-m4 -mthumb -Os -ffreestanding $(WARN) -Iinclude
ARMCCF = $(ARM)-gcc -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os -ffreestanding $(WARN) -Iinclude
F32_FLASH := 1536
F32_STATE := 300
# Without the cross compiler, say what will be installed and how big it is
# (apt's own figure: about 436 MB for gcc-arm-none-eabi on Debian 12) before
# installing it as root; otherwise print the command.
size:
	@command -v $(ARM)-gcc >/dev/null || { \
	  mb=$$(apt-cache show gcc-arm-none-eabi 2>/dev/null | awk '/^Installed-Size/ {printf "%.0f", $$2 / 1000; exit}'); \
	  echo "size: needs $(ARM)-gcc, the cross compiler in Debian's gcc-arm-none-eabi (about $${mb:-436} MB installed, with binutils-arm-none-eabi)"; \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "size: installing it now with apt-get (interrupt within 5 s to stop)"; sleep 5; \
	    apt-get install -y -q --no-install-recommends gcc-arm-none-eabi; \
	  else echo "size: sudo apt-get install -y --no-install-recommends gcc-arm-none-eabi"; exit 1; fi; }
	@mkdir -p $(B)/arm && printf '%s\n' '#include <stddef.h>' '#include "foldest/quadric.h"' \
	  'fe_quadric fe_state;' 'int fe_probe(const double *x);' \
	  'int fe_probe(const double *x) { return fe_quadric_add(&fe_state, x); }' \
	  'void *memcpy(void *d, const void *s, size_t n) { char *a = d; const char *b = s; while (n--) *a++ = *b++; return d; }' \
	  'void *memset(void *d, int c, size_t n) { char *a = d; while (n--) *a++ = (char)c; return d; }' > $(B)/arm/probe.c
	$(ARMCC) -c src/quadric.c -o $(B)/arm/quadric.o
	@$(ARMCC) -ffunction-sections -fdata-sections -nostdlib -Wl,--gc-sections -Wl,-e,fe_probe \
	  src/quadric.c $(B)/arm/probe.c -lgcc -o $(B)/arm/step.elf
	@$(ARM)-size $(B)/arm/quadric.o $(B)/arm/step.elf
	@set -- $$($(ARM)-size $(B)/arm/step.elf | tail -1); \
	  printf 'the step with its soft-double routines: %d bytes of flash; the state: %d bytes of RAM\n' $$1 $$3
	@echo "quadric.o needs only the compiler's runtime:" $$($(ARM)-nm -u $(B)/arm/quadric.o | awk '{print $$2}')
	@printf '%s\n' '#include <stddef.h>' '#include "foldest/quadric.h"' \
	  'fe_quadric_f32 fe_state;' 'int fe_probe(const float *x);' \
	  'int fe_probe(const float *x) { return fe_quadric_f32_add(&fe_state, x); }' \
	  'void *memcpy(void *d, const void *s, size_t n) { char *a = d; const char *b = s; while (n--) *a++ = *b++; return d; }' \
	  'void *memset(void *d, int c, size_t n) { char *a = d; while (n--) *a++ = (char)c; return d; }' > $(B)/arm/probe_f32.c
	$(ARMCCF) -ffunction-sections -fdata-sections -nostdlib -Wl,--gc-sections -Wl,-e,fe_probe \
	  src/quadric.c $(B)/arm/probe_f32.c -lgcc -o $(B)/arm/step_f32.elf
	@$(ARM)-size $(B)/arm/step_f32.elf
	@$(ARM)-nm -S -t d --size-sort $(B)/arm/step_f32.elf | awk '{printf "  %-26s %5d bytes\n", $$4, $$2}'
	@flash=$$($(ARM)-size $(B)/arm/step_f32.elf | awk 'NR == 2 {print $$1 + $$2}'); \
	  state=$$($(ARM)-nm -S -t d $(B)/arm/step_f32.elf | awk '$$4 == "fe_state" {print $$2 + 0}'); \
	  soft=$$($(ARM)-nm $(B)/arm/step_f32.elf | awk '$$3 ~ /^__aeabi_d|^__.*df/ {print $$3}'); \
	  printf 'the single-precision step (Cortex-M4F): %d bytes of flash (limit %d); the state: %d bytes (limit %d)\n' \
	    $$flash $(F32_FLASH) $$state $(F32_STATE); \
	  if [ -n "$$soft" ]; then echo "size: the float step pulls in soft double: $$soft"; exit 1; fi; \
	  if [ $$flash -gt $(F32_FLASH) ] || [ $$state -gt $(F32_STATE) ]; then echo "size: over the limit"; exit 1; fi

# ---------------------------------------------------------------- tests
# The runner adds every suite it finds: tests/check_<module>.c defines
# `Suite *fe_<module>_suite(void)`, listed into suites.h at build time.
$(B)/tests/suites.h: $(TEST_SRC)
	@mkdir -p $(@D)
	sed -n 's/^Suite \*\(fe_[a-z0-9_]*_suite\)(void)$$/FE_SUITE(\1)/p' $(TEST_SRC) > $@

TEST_DEFS = -DFE_TEST_CLI='"$(abspath $(CLI))"' -DFE_TEST_SRC='"$(abspath .)"'

$(B)/tests/check_foldest: $(TEST_SRC) tests/main.c tests/testutil.h tests/cli_run.h $(B)/tests/suites.h $(STATIC) $(CLI)
	$(CC) $(WARN) -O2 -g $(TEST_DEFS) -Iinclude -Itests -I$(B)/tests $(CHECK_CFLAGS) -o $@ \
	  tests/main.c $(TEST_SRC) $(STATIC) $(CHECK_LIBS) $(EXT_LIBS) $(LDFLAGS)

$(B)/san/%.o: src/%.c $(HEADERS) $(PRIV_HEADERS) $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) -O1 -g $(SAN) -Iinclude $(EXT_CFLAGS) -c $< -o $@

$(B)/tests/check_foldest_san: $(TEST_SRC) tests/main.c tests/testutil.h tests/cli_run.h $(B)/tests/suites.h $(SAN_OBJ) $(CLI)
	$(CC) $(WARN) -O1 -g $(SAN) $(TEST_DEFS) -Iinclude -Itests -I$(B)/tests $(CHECK_CFLAGS) -o $@ \
	  tests/main.c $(TEST_SRC) $(SAN_OBJ) $(CHECK_LIBS) $(EXT_LIBS)

# The parallel folds again, library and tests built with ThreadSanitizer.
$(B)/tsan/%.o: src/%.c $(HEADERS) $(PRIV_HEADERS) $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) -O1 -g $(TSAN) -Iinclude $(EXT_CFLAGS) -c $< -o $@

# The command too: its tables are parsed on threads (cli.org, "Every core
# on one file"); the tests built here run this instrumented foldest.
TSAN_CLI_OBJ := $(patsubst src/cli/%.c,$(B)/tsan/cli/%.o,$(CLI_SRC))
TSAN_CLI     := $(B)/tsan/bin/foldest
$(B)/tsan/cli/%.o: src/cli/%.c $(HEADERS) $(wildcard src/cli/*.h) $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) -O1 -g $(TSAN) -Iinclude -Isrc/cli -c $< -o $@
$(TSAN_CLI): $(TSAN_CLI_OBJ) $(TSAN_OBJ)
	@mkdir -p $(@D)
	$(CC) $(TSAN) -o $@ $(TSAN_CLI_OBJ) $(TSAN_OBJ) $(EXT_LIBS) $(CLI_LIBS)

$(B)/tests/check_foldest_tsan: $(TEST_SRC) tests/main.c tests/testutil.h tests/cli_run.h $(B)/tests/suites.h $(TSAN_OBJ) $(TSAN_CLI)
	$(CC) $(WARN) -O1 -g $(TSAN) -DFE_TEST_CLI='"$(abspath $(TSAN_CLI))"' -DFE_TEST_SRC='"$(abspath .)"' \
	  -Iinclude -Itests -I$(B)/tests $(CHECK_CFLAGS) -o $@ \
	  tests/main.c $(TEST_SRC) $(TSAN_OBJ) $(CHECK_LIBS) $(EXT_LIBS)

tests: $(B)/tests/check_foldest $(B)/tests/check_foldest_san

check: check-plain check-san check-valgrind check-install

check-plain: $(B)/tests/check_foldest all
	@echo "== tests (plain build)"
	$(B)/tests/check_foldest

check-san: $(B)/tests/check_foldest_san
	@echo "== tests (AddressSanitizer + UndefinedBehaviorSanitizer)"
	FE_TEST_QUICK=1 ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(B)/tests/check_foldest_san

# Under the sanitizers and valgrind the heavy statistical loops run smaller
# (FE_TEST_QUICK): they check memory and behaviour, the plain run the statistics.
check-valgrind: $(B)/tests/check_foldest
	@echo "== tests (valgrind memcheck)"
	CK_FORK=no FE_TEST_QUICK=1 valgrind -q --error-exitcode=99 --leak-check=full \
	  --errors-for-leak-kinds=definite,indirect,possible --show-leak-kinds=definite,indirect,possible \
	  $(B)/tests/check_foldest

check-tsan: $(B)/tests/check_foldest_tsan
	@echo "== parallel tests (ThreadSanitizer)"
	CK_RUN_SUITE=parallel FE_TEST_QUICK=1 TSAN_OPTIONS=halt_on_error=1 $(B)/tests/check_foldest_tsan
	@echo "== the command's threaded reading (ThreadSanitizer: a race ends the command with status 66)"
	CK_RUN_SUITE=threads_cli FE_TEST_QUICK=1 TSAN_OPTIONS=halt_on_error=1:exitcode=66 $(B)/tests/check_foldest_tsan

# Install into a scratch DESTDIR and build every example from it with
# pkg-config; then build tests/cxx/use_from_cxx.cpp the same way as C++17
# (every public header included from C++) and run it on the installed
# shared library.
check-install: lib
	@echo "== install into a scratch DESTDIR; build the examples with pkg-config"
	@set -e; d=$$(mktemp -d); trap 'rm -rf "$$d"' EXIT; \
	$(MAKE) -s install DESTDIR="$$d" PREFIX=/usr/local >/dev/null; \
	for e in examples/*.c; do \
	  PKG_CONFIG_SYSROOT_DIR="$$d" PKG_CONFIG_PATH="$$d/usr/local/lib/pkgconfig" \
	  sh -c 'set -e; $(CC) $(WARN) -o "$$1/$$(basename $$2 .c)" "$$2" $$(pkg-config --cflags --libs foldest)' _ "$$d" "$$e"; \
	  echo "built $$e against $$d/usr/local"; \
	done; \
	PKG_CONFIG_SYSROOT_DIR="$$d" PKG_CONFIG_PATH="$$d/usr/local/lib/pkgconfig" \
	  sh -c 'set -e; $(CXX) $(CXXWARN) -o "$$1/use_from_cxx" tests/cxx/use_from_cxx.cpp $$(pkg-config --cflags --libs foldest)' _ "$$d"; \
	LD_LIBRARY_PATH="$$d/usr/local/lib" "$$d/use_from_cxx"; \
	for m in doc/man/*.1; do \
	  f="$$d/usr/local/share/man/man1/$$(basename $$m)"; [ -f "$$f" ] || { echo "not installed: $$f"; exit 1; }; \
	  w=$$(LC_ALL=C.UTF-8 MANWIDTH=80 man --warnings -l "$$f" 2>&1 >/dev/null); \
	  [ -z "$$w" ] || { echo "$$f: $$w"; exit 1; }; \
	done; \
	c=$$(bash -c '. "$$1"; COMP_WORDS=(foldest stats --co); COMP_CWORD=2; _foldest; echo "$${COMPREPLY[*]}"' _ \
	     "$$d/usr/local/share/bash-completion/completions/foldest"); \
	[ "$$c" = "--columns" ] || { echo "bash completion: 'foldest stats --co' gave '$$c'"; exit 1; }; \
	echo "man pages and bash completion installed; the pages render without warnings"

# ---------------------------------------------------------------- acceptance
# `make accept`: foldest discover on cases drawn by an independent generator
# (tests/accept/gen.c: its own random numbers, rigs, noise and clocks; it
# includes nothing of foldest) and on the real recordings, then the dynamics
# (output-error) cases of tests/accept/gen_dyn.c, with and without their
# --order K; long, so outside `make check` and CI.  SEEDS=20 by default,
# QUICK=1 for three seeds.  `make accept-dynamics`: the dynamics section only.
$(B)/accept/gen: tests/accept/gen.c tests/accept/common.h $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) -o $@ $< -lm

$(B)/accept/gen_dyn: tests/accept/gen_dyn.c tests/accept/common.h $(B)/.deps
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) -o $@ $< -lm

ACCEPT_ENV = FOLDEST=$(CLI) GEN=$(B)/accept/gen GEN_DYN=$(B)/accept/gen_dyn ACCEPT_OUT=$(B)/accept/runs

accept: all $(B)/accept/gen $(B)/accept/gen_dyn
	$(ACCEPT_ENV) python3 tests/accept/run.py

accept-dynamics: all $(B)/accept/gen_dyn
	$(ACCEPT_ENV) python3 tests/accept/run.py --dynamics

# ---------------------------------------------------------------- mutation testing
# `make mutate`: single-point mutants generated from src/*.c by
# tests/mutate/mutate.py (operators, constants, dropped factors, skipped
# checks; in proportion to each module's size, from SEED), each built into
# the plain test binary and the command and run against the fast suites of
# its module (FE_TEST_QUICK); kill rate per module, survivors listed, report
# in $(B)/mutate/report.txt.  MUTANTS=20 draws a random sample instead of the
# full set; MUTATE_MIN fails below that overall rate (percent).  One core.
# See tests/mutate/README.md.
MUTANTS        ?= 0
SEED           ?= 1
MUTATE_EXCLUDE ?=
MUTATE_MIN     ?= 0
# Every documented error code of every public function is produced by a
# test statement, or explained in tests/audit/codes_explained.txt; every
# option of every command is used by a test that runs the command, or
# explained in tests/audit/options_explained.txt.
audit:
	python3 tests/audit/codes.py
	python3 tests/audit/options.py

mutate: lib cli $(B)/tests/suites.h
	python3 tests/mutate/mutate.py --mutants $(MUTANTS) --seed $(SEED) --exclude '$(MUTATE_EXCLUDE)' \
	  --min-rate $(MUTATE_MIN) $(if $(MUTANT_IDS),--ids '$(MUTANT_IDS)') --build $(B) --cc '$(CC)' \
	  --cflags '$(filter-out -Werror,$(WARN)) $(CFLAGS)' --ext-cflags '$(EXT_CFLAGS)' \
	  --ext-libs '$(EXT_LIBS) $(CLI_LIBS)' --check-cflags '$(CHECK_CFLAGS)' --check-libs '$(CHECK_LIBS)'

# ---------------------------------------------------------------- fuzzing
# libFuzzer harnesses (tests/fuzz/fuzz_*.c), clang with ASan and UBSan; the
# library and the command line are rebuilt instrumented ($(B)/fuzz), the
# CLI with its main renamed fe_cli_main.  `make fuzz` runs each harness
# FUZZ_TIME seconds from its seed corpus (tests/fuzz/corpus/NAME, kept in
# git) into $(B)/fuzz/corpus/NAME; a crash leaves $(B)/fuzz/crash-* and
# fails.  Replay one: $(B)/fuzz/fuzz_NAME /absolute/FILE (FE_FUZZ_VERBOSE=1
# shows the command line's messages; fuzz_cli runs in a scratch directory).
FUZZ_CC      ?= clang
FUZZ_TIME    ?= 120
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_CFLAGS  := $(WARN) -O1 -g $(FUZZ_SAN) -fsanitize=fuzzer-no-link
FUZZERS      := $(patsubst tests/fuzz/%.c,$(B)/fuzz/%,$(wildcard tests/fuzz/fuzz_*.c))
FUZZ_LIB_OBJ := $(patsubst src/%.c,$(B)/fuzz/obj/%.o,$(LIB_SRC))
FUZZ_CLI_OBJ := $(patsubst src/cli/%.c,$(B)/fuzz/obj/cli/%.o,$(CLI_SRC))

$(B)/fuzz/obj/%.o: src/%.c $(HEADERS) $(PRIV_HEADERS) $(B)/.deps
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -Iinclude $(EXT_CFLAGS) -c $< -o $@
$(B)/fuzz/obj/cli/%.o: src/cli/%.c $(HEADERS) $(wildcard src/cli/*.h) $(B)/.deps
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -Dmain=fe_cli_main -DFE_CLI_KEEP_STDOUT -Iinclude -Isrc/cli -c $< -o $@
$(B)/fuzz/fuzz_%: tests/fuzz/fuzz_%.c $(wildcard tests/fuzz/*.h) $(FUZZ_LIB_OBJ) $(FUZZ_CLI_OBJ)
	$(FUZZ_CC) $(WARN) -Wno-unused-function -O1 -g $(FUZZ_SAN) -fsanitize=fuzzer -Iinclude -Itests/fuzz \
	  -o $@ $< $(FUZZ_CLI_OBJ) $(FUZZ_LIB_OBJ) $(EXT_LIBS) $(CLI_LIBS)

# Keep the instrumented objects (make would delete them as intermediates).
.SECONDARY: $(FUZZ_LIB_OBJ) $(FUZZ_CLI_OBJ)

fuzz-build: $(FUZZERS)

fuzz: $(FUZZERS)
	@set -e; for f in $(FUZZERS); do n=$$(basename $$f); \
	  mkdir -p $(B)/fuzz/corpus/$$n tests/fuzz/corpus/$$n; \
	  echo "== $$n for $(FUZZ_TIME) s"; \
	  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  $$f -max_total_time=$(FUZZ_TIME) -timeout=20 -rss_limit_mb=2048 -max_len=4096 \
	    -print_final_stats=1 -artifact_prefix=$(abspath $(B)/fuzz)/ \
	    $(abspath $(B)/fuzz/corpus)/$$n $(abspath tests/fuzz/corpus)/$$n > $(B)/fuzz/$$n.log 2>&1 \
	    || { tail -60 $(B)/fuzz/$$n.log; echo "fuzz: $$n failed; see $(B)/fuzz/$$n.log"; exit 1; }; \
	  grep -E '^stat::(number_of_executed_units|new_units_added)' $(B)/fuzz/$$n.log | tr '\n' ' '; echo; \
	done

# ---------------------------------------------------------------- coverage
# The library and the command line rebuilt with gcov instrumentation in
# $(B)/cov, every suite run once (the CLI suites run the instrumented
# foldest), and gcovr's line and branch coverage of src/: a summary on the
# terminal, per file in $(B)/cov/coverage.txt and $(B)/cov/branches.txt,
# HTML in $(B)/cov/html/.  What stays uncovered, and why: README.md.
# FE_NO_CLONES: one instance of the moment kernel's text (the portable one),
# not three of which this processor runs one.
COV_B := $(B)/cov
coverage: $(B)/.deps
	@rm -rf $(COV_B)/obj $(COV_B)/html && find $(COV_B) -name '*.gcda' -delete 2>/dev/null || true
	$(MAKE) -s B=$(COV_B) CFLAGS='-O0 -g --coverage -fprofile-update=atomic -DFE_NO_CLONES' LDFLAGS=--coverage $(COV_B)/tests/check_foldest examples
	@mkdir -p $(COV_B)/html
	FE_TEST_QUICK=1 $(COV_B)/tests/check_foldest
	gcovr -r . --filter 'src/' --object-directory $(COV_B)/obj --txt $(COV_B)/coverage.txt \
	  --html-details $(COV_B)/html/index.html --print-summary
	@gcovr -r . --filter 'src/' --object-directory $(COV_B)/obj --branches --txt $(COV_B)/branches.txt
	@echo "per file: $(COV_B)/coverage.txt (lines), $(COV_B)/branches.txt; open $(COV_B)/html/index.html"

# ---------------------------------------------------------------- static analysis
# cppcheck and clang-tidy (configuration: .clang-tidy) over src/ and
# include/; any finding fails.  Headers are checked through the sources that
# include them.
LINT_FLAGS = -std=c11 -D_POSIX_C_SOURCE=200809L -Iinclude -Isrc/cli $(EXT_CFLAGS)
lint: $(B)/.deps
	cppcheck -q --std=c11 --enable=warning,portability,performance --inline-suppr \
	  --error-exitcode=1 --suppress=missingIncludeSystem -j2 -Iinclude -Isrc/cli src include
	@echo "cppcheck: clean"
	@status=0; for f in $(LIB_SRC) $(CLI_SRC); do \
	  clang-tidy -quiet $$f -- $(LINT_FLAGS) 2>/dev/null || status=1; \
	done; [ $$status = 0 ] && echo "clang-tidy: clean"; exit $$status

# ---------------------------------------------------------------- literate
# Tangle into a scratch copy, then copy only the files whose content changed,
# so that make rebuilds only what really changed.
TANGLE_TMP := $(B)/tangle
.PHONY: tangle-scratch
tangle-scratch: $(B)/.deps
	@rm -rf $(TANGLE_TMP) && mkdir -p $(TANGLE_TMP)/literate
	@cp $(ORG) $(TANGLE_TMP)/literate/
	@cd $(TANGLE_TMP)/literate && emacs --batch -Q -l ../../../literate/tangle.el \
	  -f fe-tangle $(notdir $(ORG)) 2>&1 | grep -v '^Tangled' || true

tangle: tangle-scratch
	@cd $(TANGLE_TMP) && find include src -type f | sort | while read f; do \
	  if ! cmp -s "$$f" "../../$$f"; then mkdir -p "../../$$(dirname $$f)"; \
	    cp "$$f" "../../$$f"; echo "tangled $$f"; fi; \
	done

check-tangle: tangle-scratch
	@status=0; \
	for f in $$(cd $(TANGLE_TMP) && find include src -type f | sort); do \
	  cmp -s "$(TANGLE_TMP)/$$f" "$$f" || { echo "check-tangle: $$f differs from what literate/ produces"; status=1; }; \
	done; \
	for f in $$(find include src -type f | sort); do \
	  [ -f "$(TANGLE_TMP)/$$f" ] || { echo "check-tangle: $$f is not produced by any literate document"; status=1; }; \
	done; \
	for f in $$(find include src tests examples bench -path tests/fuzz/corpus -prune -o -type f \
	              \( -name '*.[ch]' -o -name '*.cpp' -o -name '*.sh' \) -print | sort) Makefile .ci/run .ci/deps literate/tangle.el \
	              $(wildcard literate/figures/*.py); do \
	  head -2 "$$f" | grep -q 'SPDX-License-Identifier: MIT' || { echo "check-tangle: $$f has no SPDX line at its top"; status=1; }; \
	done; \
	[ $$status = 0 ] && echo "check-tangle: include/ and src/ match literate/*.org; every source file carries its SPDX line"; exit $$status

# The book's figures, drawn by the project's own programs when the book is
# woven: literate/figures/*.py run foldest on data they generate (and on
# ../shared/data when it is there), count, and draw with gnuplot into
# $(B)/doc/figures, beside a .dat of the numbers and the .gp that draws them.
# The discovery figure (160 analyses, about 30 s) is redrawn when its script
# or the command changed, `rm -rf $(B)/doc/figures && make figures` redraws
# it anyway; the sphere figures (about a second) are redrawn every time, so
# that they follow ../shared/data as it comes and goes.
FIG          := $(B)/doc/figures
FIGURES      := $(FIG)/discover-noise.svg $(FIG)/sphere-synthetic.svg
figures: $(FIGURES)
$(FIG)/discover-noise.svg: literate/figures/discover_noise.py $(CLI)
	@mkdir -p $(@D)
	@FOLDEST=$(abspath $(CLI)) nice python3 $< $(@D)
$(FIG)/sphere-synthetic.svg: literate/figures/sphere_calibration.py $(CLI) FORCE
	@mkdir -p $(@D)
	@FOLDEST=$(abspath $(CLI)) nice python3 $< $(@D)
FORCE:

doc: $(B)/.deps figures
	@mkdir -p $(B)/doc
	@emacs --batch -Q -l literate/tangle.el -f fe-weave $(B)/doc $(ORG) >$(B)/doc/weave.log 2>&1 \
	  || { cat $(B)/doc/weave.log; echo "doc: weaving failed"; exit 1; }
	@grep -E '^Wove|rror' $(B)/doc/weave.log || true
	@echo "open $(B)/doc/index.html"

# Every woven page opened in headless Chromium after MathJax has run: no raw
# TeX may survive in the text a reader sees, and no MathJax error be shown.
check-doc: doc
	@python3 tests/doc/check_doc.py $(B)/doc

# ---------------------------------------------------------------- demo
demo: all
	@sh examples/demo.sh $(B)

# Every example program, one after the other.
run-examples: all
	@for e in $(EXAMPLES); do echo "== $$e"; $$e || exit 1; echo; done

# ---------------------------------------------------------------- install
install: lib cli
	install -d $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(INCLUDEDIR)/foldest
	install -m 644 include/foldest.h $(DESTDIR)$(INCLUDEDIR)/
	install -m 644 $(wildcard include/foldest/*.h) $(DESTDIR)$(INCLUDEDIR)/foldest/
	install -m 644 $(STATIC) $(DESTDIR)$(LIBDIR)/
	install -m 755 $(SHARED) $(DESTDIR)$(LIBDIR)/
	ln -sf libfoldest.so.$(VERSION) $(DESTDIR)$(LIBDIR)/libfoldest.so.$(SOVERSION)
	ln -sf libfoldest.so.$(VERSION) $(DESTDIR)$(LIBDIR)/libfoldest.so
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(LIBDIR)|' -e 's|@INCLUDEDIR@|$(INCLUDEDIR)|' \
	    -e 's|@VERSION@|$(VERSION)|' foldest.pc.in > $(DESTDIR)$(LIBDIR)/pkgconfig/foldest.pc
	$(if $(CLI_OBJ),install -d $(DESTDIR)$(BINDIR) && install -m 755 $(CLI) $(DESTDIR)$(BINDIR)/,)
	install -d $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(COMPLETIONDIR)
	install -m 644 $(wildcard doc/man/*.1) $(DESTDIR)$(MANDIR)/man1/
	install -m 644 doc/completion/foldest.bash $(DESTDIR)$(COMPLETIONDIR)/foldest

uninstall:
	rm -rf $(DESTDIR)$(INCLUDEDIR)/foldest $(DESTDIR)$(INCLUDEDIR)/foldest.h
	rm -f $(DESTDIR)$(LIBDIR)/libfoldest.* $(DESTDIR)$(LIBDIR)/pkgconfig/foldest.pc $(DESTDIR)$(BINDIR)/foldest
	rm -f $(addprefix $(DESTDIR)$(MANDIR)/man1/,$(notdir $(wildcard doc/man/*.1))) $(DESTDIR)$(COMPLETIONDIR)/foldest

clean:
	rm -rf $(B)
