# shadowlab -- build, test, demo, bench.
# `make` builds build/shadowlab; `make test` and `make demo` install missing
# Debian packages first (scripts/deps.sh), then build and run.

# Build on every core unless a -j is given (`make -j1` builds one file at a time):
# a fresh clone's make test compiles the library three times (optimised,
# sanitized, fuzzing): 195 s one file at a time, ~96 s on 2 cores.
MAKEFLAGS += -j$(shell nproc)
CC      ?= cc
CXX     ?= c++
# Vectorise loops whenever the cost model says it pays (the -O2 default, "very cheap", skips
# loops of unknown trip count, which is every span of the rasterizer).
OPT     ?= -O2 -fvect-cost-model=dynamic
# snprintf into bounded buffers truncates by design: that warning is off.
WARN    := -Wall -Wextra -Werror -Wno-format-truncation
INCS     = -Isrc -I$(B)/gen -I/usr/include/lua5.4 -I/usr/include/OpenEXR
CFLAGS   = -std=c11 $(OPT) -g $(WARN) -fopenmp -fPIC $(INCS) -D_DEFAULT_SOURCE
# Embree 3 and OpenEXRCore have no usable pkg-config entry for C: link by name.
LIBS    := -llua5.4 -lembree3 -lOpenEXRCore-3_1 -lz -ldl -lm -fopenmp
SAN     := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined

# Build folder; several working copies of one checkout can use their own (make B=build-x).
B       ?= build
DEPS    := $(B)/deps.stamp
LIB_SRC := $(shell find src -name '*.c' ! -path 'src/cli/main.c' | sort)
LIB_OBJ := $(LIB_SRC:%.c=$(B)/obj/%.o)
SAN_OBJ := $(LIB_SRC:%.c=$(B)/san/%.o)
TEST_SRC:= $(sort $(wildcard tests/unit/*.c))
TEST_OBJ:= $(TEST_SRC:%.c=$(B)/obj/%.o)
TEST_SAN:= $(TEST_SRC:%.c=$(B)/san/%.o)
# The stability suite's own test binary (tests/stability), under ASan + UBSan.
STAB_SAN:= $(patsubst %.c,$(B)/san/%.o,$(sort $(wildcard tests/stability/*.c)))
# Fuzzers (libFuzzer needs clang): the library below the front ends again,
# instrumented for coverage with ASan + UBSan (gcc's build is the -Werror
# gate; clang's own extra warnings do not stop it), and one harness per
# parser in tests/fuzz/fuzz_*.c.
FUZZ_CC := clang
FUZZ_SAN:= -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_OBJ:= $(patsubst %.c,$(B)/fuzz/%.o,$(filter-out src/cli/% src/lua/%,$(LIB_SRC)))
FUZZERS := $(patsubst tests/fuzz/%.c,$(B)/%,$(sort $(wildcard tests/fuzz/fuzz_*.c)))
FUZZ_SECONDS ?= 600
PLUGIN  := $(B)/libshadowlab_oiio.so
# The Lua module for a plain lua5.4: require "shadowlab" with package.cpath = "build/?.so;...".
LUAMOD  := $(B)/shadowlab.so

.PHONY: all deps test test-unit demo bench bench-baseline docs clean fuzz fuzzers FORCE
all: $(B)/shadowlab $(PLUGIN) $(LUAMOD)

$(DEPS): scripts/deps.sh
	@./scripts/deps.sh
	@mkdir -p $(B) && touch $@
deps:
	./scripts/deps.sh

$(B)/obj/%.o: %.c $(DEPS)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -MMD -MP -c $< -o $@
$(B)/san/%.o: %.c $(DEPS)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -O1 $(SAN) -MMD -MP -c $< -o $@

# The git commit goes into every record; rewritten only when it changes. A
# tree that differs from the commit in what is built or read at run time
# (src, lua, tests, Makefile: modified or untracked files alike) is
# COMMIT-dirty-HASH, HASH the first 8 hex digits of the SHA-1 of that
# difference, and SHADOWLAB_DIRTY lists the paths that differ.
STAMPED := src lua tests Makefile
$(B)/gen/version.h: FORCE
	@mkdir -p $(dir $@)
	@c=$$(git rev-parse --short=12 HEAD 2>/dev/null || echo unknown); \
	 files=$$(git status --porcelain --untracked-files=all -- $(STAMPED) 2>/dev/null | cut -c4- | tr -d '"\\' | \
	          tr '\n' ' ' | sed 's/ $$//'); \
	 if [ -n "$$files" ]; then \
	   h=$$( { git diff HEAD -- $(STAMPED); git ls-files -o --exclude-standard -- $(STAMPED) | xargs -r cat; } \
	         2>/dev/null | sha1sum | cut -c1-8); c="$$c-dirty-$$h"; fi; \
	 printf '#define SHADOWLAB_COMMIT "%s"\n#define SHADOWLAB_DIRTY "%.480s"\n' "$$c" "$$files" > $@.new; \
	 cmp -s $@.new $@ && rm -f $@.new || mv $@.new $@
$(B)/obj/src/lab/record.o $(B)/san/src/lab/record.o: $(B)/gen/version.h
$(B)/fuzz/src/lab/record.o $(B)/fuzz/src/lua/lshadowlab.o: $(B)/gen/version.h
$(B)/obj/src/lua/lshadowlab.o $(B)/san/src/lua/lshadowlab.o: $(B)/gen/version.h

$(B)/libshadowlab.a: $(LIB_OBJ)
	ar rcs $@ $^
$(B)/shadowlab: $(B)/obj/src/cli/main.o $(B)/libshadowlab.a
	$(CC) -o $@ $^ $(LIBS)
# lua5.4 provides Lua itself (it exports the C API): liblua is not linked in.
$(LUAMOD): $(filter $(B)/obj/src/lua/%,$(LIB_OBJ)) $(B)/libshadowlab.a
	$(CC) -shared -o $@ $^ $(filter-out -llua5.4,$(LIBS))
# OpenImageIO (C++, ~280 ms to load) lives in a plugin opened on first use.
$(PLUGIN): src/io/oiio_plugin.cpp src/io/oiio_plugin.h $(DEPS)
	$(CXX) -std=c++17 $(OPT) -Wall -Wextra -Werror -shared -fPIC -Isrc $< -o $@ \
	    $$(pkg-config --cflags --libs OpenImageIO)

$(B)/test_unit: $(TEST_OBJ) $(B)/libshadowlab.a
	$(CC) -o $@ $^ $(LIBS)
$(B)/test_unit_san: $(TEST_SAN) $(SAN_OBJ)
	$(CC) $(SAN) -o $@ $^ $(LIBS)
$(B)/test_stability_san: $(STAB_SAN) $(SAN_OBJ)
	$(CC) $(SAN) -o $@ $^ $(LIBS)
# The CLI on the sanitized objects: tests/run.sh runs the CLI tests and the
# quick stability matrix with it (it finds the plugin next to itself).
$(B)/shadowlab_san: $(B)/san/src/cli/main.o $(SAN_OBJ)
	$(CC) $(SAN) -o $@ $^ $(LIBS)

$(B)/fuzz/%.o: %.c $(DEPS)
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(filter-out $(OPT),$(CFLAGS)) -O1 -Wno-error -Wno-unknown-warning-option $(FUZZ_SAN) \
	    -fsanitize=fuzzer-no-link -MMD -MP -c $< -o $@
$(B)/fuzz_%: $(B)/fuzz/tests/fuzz/fuzz_%.o $(FUZZ_OBJ)
	$(FUZZ_CC) $(FUZZ_SAN) -fsanitize=fuzzer -o $@ $^ $(LIBS)
fuzzers: $(FUZZERS)
# Kept between builds (as intermediates of the pattern rules they would be
# deleted, and every fuzzer relink would recompile the whole library).
.SECONDARY: $(FUZZ_OBJ) $(FUZZERS:$(B)/fuzz_%=$(B)/fuzz/tests/fuzz/fuzz_%.o)
# The long fuzz run (README): every harness for FUZZ_SECONDS, new inputs kept in build/fuzz-corpus.
fuzz: $(FUZZERS) $(PLUGIN)
	./tests/fuzz/run.sh $(B) $(FUZZ_SECONDS) 1

# The whole suite (tests/run.sh): unit, CLI and stability tests under ASan+UBSan, Lua tests on the optimised build.
test: all $(B)/test_unit_san $(B)/test_stability_san $(B)/shadowlab_san $(FUZZERS)
	@B=$(B) ./tests/run.sh
test-unit: all $(B)/test_unit
	SHADOWLAB_MODEL_PATH=$${SHADOWLAB_MODEL_PATH:-../shared/models} SHADOWLAB_PLUGIN_DIR=$(CURDIR)/$(B) ./$(B)/test_unit $(T)

demo: all
	./scripts/demo.sh $(B)/shadowlab reports/demo

# The technique reference and the README's technique table are generated from the registry.
docs: all
	./scripts/docs.sh $(B)/shadowlab

bench: all
	$(MAKE) -C bench

# A finished `make bench`'s figures (reports/bench) kept as the baseline the next reports compare with.
bench-baseline:
	./bench/run.sh --save-baseline

clean:
	rm -rf $(B)

-include $(B)/san/src/cli/main.d $(LIB_OBJ:.o=.d) $(SAN_OBJ:.o=.d) $(TEST_OBJ:.o=.d) $(TEST_SAN:.o=.d) $(STAB_SAN:.o=.d) $(FUZZ_OBJ:.o=.d)
