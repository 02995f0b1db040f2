# umbra — one non-recursive Makefile.
#   make            build/librenderer.a, build/umbra-render, build/umbrad
#   make run        install deps, build, start umbrad on 127.0.0.1:8080 (UMBRA_LISTEN=ADDR:PORT for another)
#   make test       install deps, build, run every test (last line: "N passed, N failed")
#   make test-asan  the same suite built with AddressSanitizer + UBSan
#   make fuzz       libFuzzer targets in build/fuzz (clang); make test runs each briefly
#   make bench      warm-process and HTTP benchmarks of ../shared/bench, the floor, the ratio table
#   make bench-quick  only the ratio table's rows (BENCH_ONLY=ratios)
#   make bench-farm   only the farm benchmark on new models: farm CLI, umbrad c=4, f3d (BENCH_ONLY=farm)
#   make cluster    three umbrad behind HAProxy on 127.0.0.1:8080 (stats :8404; CLUSTER_PORT, CLUSTER_STATS_PORT), Ctrl-C stops
#   make test-cluster   the HAProxy fail-over test alone (also part of make test)
#   make test-farm      umbra-render --server on three daemons behind HAProxy (also part of make test)
#   make bench-cluster  1 vs 3 daemons, cache hit rates with and without affinity
#   make bench-farm-remote  the local farm against --server on 3 daemons, 300 models
#   make check-deploy   haproxy -c, systemd-analyze verify/security, k8s manifest checks
#   make sizes      files over ~600 lines and functions over ~80 in api/ renderer/ server/, test files over ~600 (a list)
#   make soak       10,000 mixed requests against one umbrad; RSS and descriptors must stay flat
BUILD ?= build
SHARED ?= ../shared
CC ?= cc
# C++ for api/draco.cpp alone (libdraco has no C API) and its test encoder (tests/util/).
CXX ?= c++
GLSLANG ?= glslangValidator
# The packages of each module (server -> api -> renderer): each compiles with its own packages'
# cflags only; everything links with all of them.
PKGS_RENDERER := vulkan
PKGS_API := jansson libpng OpenEXR zlib assimp libjpeg libseccomp libwebp libavif libdeflate draco
PKGS_SERVER := libmicrohttpd
PKGS := $(PKGS_RENDERER) $(PKGS_API) $(PKGS_SERVER)

OPT ?= -O2
SAN ?=
CFLAGS ?= $(OPT) -g
CFLAGS += -std=c11 -D_GNU_SOURCE -Wall -Wextra -Werror -Wno-missing-field-initializers \
          -fno-strict-aliasing -pthread -MMD -MP $(SAN)
# The C++ shim: the same warnings; no vptr check (clang's C link has no C++ UBSan runtime).
CXXFLAGS ?= $(OPT) -g
CXXFLAGS += -std=c++17 -Wall -Wextra -Werror -fno-strict-aliasing -pthread -MMD -MP $(SAN) \
            $(if $(SAN),-fno-sanitize=vptr)
LDFLAGS += -pthread $(SAN)
# Each module sees only the headers it may use (server -> api -> renderer -> shaders): an
# include across the layering is a compile error, not a review comment. Tests see everything.
# Their packages' cflags likewise (PKG_CFLAGS_* below): the renderer gets Vulkan's, api/ those of
# jansson, Assimp, libpng, OpenEXR, zlib, libjpeg, libseccomp, libwebp, libavif and libdeflate (meshoptimizer has no .pc),
# the server libmicrohttpd's.
INC_RENDERER = -Irenderer/include -Irenderer -Ishaders -I$(BUILD)/shaders $(PKG_CFLAGS_RENDERER)
INC_API = -Irenderer/include -Iapi $(PKG_CFLAGS_API)
INC_SERVER = -Irenderer/include -Iapi -Iserver -I$(BUILD)/www $(PKG_CFLAGS_SERVER)
INC_TESTS = -Itests/util -Irenderer/include -Irenderer -Ishaders -Iapi -Iserver -I$(BUILD)/shaders -I$(BUILD)/www \
            $(PKG_CFLAGS)
# pkg-config's answer is checked (pkg-check below), not silenced: a missing package fails the
# build with pkg-config's own message instead of a confusing compile or link error later.
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS))
PKG_STATUS := $(.SHELLSTATUS)
PKG_LIBS := $(shell pkg-config --libs $(PKGS))
# (Their errors show once, in pkg-check, which runs before any compile.)
PKG_CFLAGS_RENDERER := $(shell pkg-config --cflags $(PKGS_RENDERER) 2>/dev/null)
PKG_CFLAGS_API := $(shell pkg-config --cflags $(PKGS_API) 2>/dev/null)
PKG_CFLAGS_SERVER := $(shell pkg-config --cflags $(PKGS_SERVER) 2>/dev/null)
# The build's version (in /v1/info and the ETag): the commit, "-dirty" with local changes.
# Without .git (a container build, a tarball): `make UMBRA_VERSION=...` or a VERSION file.
ifeq ($(UMBRA_VERSION),)
UMBRA_VERSION := $(shell git describe --always --dirty 2>/dev/null || cat VERSION 2>/dev/null || echo unknown)
endif
CFLAGS += -DUMBRA_VERSION=\"$(UMBRA_VERSION)\"
# meshoptimizer (api/model_lod.c) ships no pkg-config file in Debian 12; libstdc++ for the
# Draco shim (api/draco.cpp), linked by the C driver.
LIBS := $(PKG_LIBS) -lmeshoptimizer -lstdc++ -lm

RND_SRC := $(wildcard renderer/*.c)
API_SRC := $(wildcard api/*.c)
API_CXX_SRC := $(wildcard api/*.cpp)
FARM_SRC := server/cli.c server/explain_text.c server/farm.c server/farm_local.c server/farm_remote.c server/farm_report.c server/http_client.c
SRV_SRC := $(filter-out $(FARM_SRC),$(wildcard server/*.c))
UNIT_SRC := $(wildcard tests/unit/*.c)
GPU_SRC := $(wildcard tests/gpu/*.c)
# tests/util/: the harness (test.h, test_main.c) and helpers both test binaries share.
UTIL_SRC := $(wildcard tests/util/*.c)
UTIL_CXX_SRC := $(wildcard tests/util/*.cpp)
SHADERS := $(wildcard shaders/*.vert shaders/*.frag shaders/*.comp)
SHADER_HDRS := $(patsubst shaders/%,$(BUILD)/shaders/%.spv.h,$(SHADERS))

RND_OBJ := $(RND_SRC:%.c=$(BUILD)/obj/%.o)
API_OBJ := $(API_SRC:%.c=$(BUILD)/obj/%.o) $(API_CXX_SRC:%.cpp=$(BUILD)/obj/%.o)
SRV_OBJ := $(SRV_SRC:%.c=$(BUILD)/obj/%.o)
UTIL_OBJ := $(UTIL_SRC:%.c=$(BUILD)/obj/%.o) $(UTIL_CXX_SRC:%.cpp=$(BUILD)/obj/%.o)
UNIT_OBJ := $(UNIT_SRC:%.c=$(BUILD)/obj/%.o) $(UTIL_OBJ)
GPU_OBJ := $(GPU_SRC:%.c=$(BUILD)/obj/%.o) $(UTIL_OBJ)

BINS := $(BUILD)/librenderer.a $(BUILD)/libapi.a $(BUILD)/umbra-render $(BUILD)/umbra-import $(BUILD)/tests/unit_tests
ifneq ($(SRV_SRC),)
BINS += $(BUILD)/umbrad
endif
ifneq ($(GPU_SRC),)
BINS += $(BUILD)/tests/gpu_tests
endif

.PHONY: pkg-check all deps run test test-asan bench bench-quick bench-tools fuzz fuzz-long fuzz-targets soak clean cluster test-cluster test-farm bench-cluster bench-farm-remote check-deploy sizes print-version
all: $(BINS)

deps:
	@sh deploy/install-deps.sh
bench-deps:
	@sh deploy/install-deps.sh --bench

pkg-check:
	@[ "$(PKG_STATUS)" = 0 ] || { echo "pkg-config cannot find every one of: $(PKGS) (make deps installs them)"; \
	  pkg-config --cflags $(PKGS) >/dev/null; exit 1; }

# Shaders: SPIR-V embedded as C arrays (spv_<file>_<stage>), for Vulkan 1.3 (the device's version).
$(BUILD)/shaders/%.spv.h: shaders/% $(wildcard shaders/*.h shaders/*.glsl) | $(BUILD)/shaders
	$(GLSLANG) -V --target-env vulkan1.3 -Ishaders --vn spv_$(subst .,_,$*) -o $@ $< >/dev/null || \
	  { $(GLSLANG) -V --target-env vulkan1.3 -Ishaders -o /dev/null $<; exit 1; }
$(BUILD)/shaders:
	@mkdir -p $@

$(BUILD)/obj/%.o: %.c | pkg-check
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(INC) -c -o $@ $<
$(BUILD)/obj/%.o: %.cpp | pkg-check
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(INC) -c -o $@ $<
$(BUILD)/obj/renderer/%.o: INC := $(INC_RENDERER)
$(BUILD)/obj/api/%.o: INC := $(INC_API)
$(BUILD)/obj/server/%.o: INC := $(INC_SERVER)
$(BUILD)/obj/tests/%.o: INC := $(INC_TESTS)
# The renderer embeds the SPIR-V headers: they must exist before its first compile; after
# that the dependency files (-MMD) rebuild only the objects that include a changed one.
$(RND_OBJ): | $(SHADER_HDRS)

$(BUILD)/librenderer.a: $(RND_OBJ)
	@rm -f $@; ar rcs $@ $^
# The playground page (server/www/) inlined into one HTML document, with the bench scenes of
# $(SHARED)/bench when present and the scene schema (for the editor's help), and embedded in umbrad as a C array (xxd -i).
BENCH_JSON := $(wildcard $(SHARED)/bench/*.json)
$(BUILD)/www/playground_page.h: $(wildcard server/www/*) api/scene.schema.json $(BENCH_JSON)
	@mkdir -p $(dir $@)
	sh server/www/embed.sh server/www $(BUILD)/www api/scene.schema.json $(BENCH_JSON)
$(BUILD)/obj/server/playground.o: $(BUILD)/www/playground_page.h
$(BUILD)/libapi.a: $(API_OBJ)
	@rm -f $@; ar rcs $@ $^

$(BUILD)/umbra-render: $(FARM_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/server/buf.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
# The sandboxed model importer (api/sandbox.h), started by umbrad and umbra-render; found next to
# them. --as-needed: it maps only the libraries it uses (no Vulkan, no HTTP).
$(BUILD)/umbra-import: $(BUILD)/obj/api/helper/umbra_import.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -Wl,--as-needed -o $@ $^ $(LIBS)
$(BUILD)/umbrad: $(SRV_OBJ) $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
# flags.o (+ admit.o and origin.o, which it calls): the unit tests cover srv_default_workers() (cgroup CPU quota);
# origin.o: the Host and Origin rules (test_origin.c);
# negotiate.o and buf.o: Accept, Content-Type, ETag and the JSON escaper (test_negotiate.c);
# queue.o: srv_queue_pop_idle; gate.o: the device gate; clock.o: what queue, admit and gate wait with;
# ranges.o: connections per address range (test_ranges.c).
$(BUILD)/tests/unit_tests: $(UNIT_OBJ) $(BUILD)/obj/server/http_client.o $(BUILD)/obj/server/clock.o $(BUILD)/obj/server/gate.o $(BUILD)/obj/server/flags.o $(BUILD)/obj/server/log.o $(BUILD)/obj/server/admit.o $(BUILD)/obj/server/origin.o $(BUILD)/obj/server/negotiate.o $(BUILD)/obj/server/buf.o $(BUILD)/obj/server/queue.o $(BUILD)/obj/server/ranges.o $(BUILD)/obj/server/results.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/gpu_tests: $(GPU_OBJ) $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)

# umbrad's defaults (127.0.0.1:8080); its UMBRA_* variables change them (UMBRA_LISTEN=ADDR:PORT).
run: deps
	@$(MAKE) --no-print-directory all
	$(BUILD)/umbrad

test: deps
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory fuzz
	@BUILD=$(BUILD) SHARED=$(SHARED) FUZZ_BUILD=$(FUZZ_BUILD) sh tests/run.sh

test-asan: deps
	@$(MAKE) --no-print-directory BUILD=build/asan OPT=-O1 \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" all
	@BUILD=build/asan SHARED=$(SHARED) ASAN=1 sh tests/run.sh

# tests/run.sh runs a 1,000-request soak; this is the full one (SOAK_N=N for another size).
soak: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) UMBRA_VALIDATION=1 sh tests/http/soak.sh

bench: bench-deps bench-tools
	@BUILD=$(BUILD) SHARED=$(SHARED) sh tests/bench.sh

# Only what the ratio table needs, fewer runs (a few minutes instead of a quarter of an hour).
bench-quick: bench-deps bench-tools
	@BUILD=$(BUILD) SHARED=$(SHARED) BENCH_ONLY=ratios sh tests/bench.sh

# The farm benchmark on new models alone (tests/bench/farm_bench.py); needs only the binaries.
.PHONY: bench-farm bench-deps
bench-farm: bench-deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) SHARED=$(SHARED) BENCH_ONLY=farm sh tests/bench.sh

# The floor (../shared/floor, read-only) builds out of tree into $(BUILD)/floor.
# After `all` (not beside it): `make -j2 all bench-tools` ran two makes writing the playground page at once.
bench-tools: all
	@$(MAKE) --no-print-directory all $(BUILD)/tests/bench $(BUILD)/tests/http_bench $(BUILD)/tests/import_bench $(BUILD)/tests/import_compare \
		$(BUILD)/tests/edge_error
	@$(MAKE) --no-print-directory -f $(SHARED)/floor/Makefile B=$(BUILD)/floor

$(BUILD)/tests/bench: $(BUILD)/obj/tests/bench/bench.o $(BUILD)/obj/tests/util/util.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/import_bench: $(BUILD)/obj/tests/bench/import_bench.o $(BUILD)/obj/tests/util/util.o $(BUILD)/libapi.a \
		$(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/import_compare: $(BUILD)/obj/tests/bench/import_compare.o $(BUILD)/obj/tests/util/util.o \
		$(BUILD)/obj/tests/util/model_compare.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/edge_error: $(BUILD)/obj/tests/bench/edge_error.o
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ -lpng16 -lm
$(BUILD)/tests/http_bench: $(BUILD)/obj/tests/bench/http_bench.o
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^

# The balancer's and its stats page's ports (0 = any free port).
CLUSTER_PORT ?= 8080
CLUSTER_STATS_PORT ?= 8404
cluster: deps
	@$(MAKE) --no-print-directory all
	python3 deploy/cluster.py up --build $(BUILD) --port $(CLUSTER_PORT) --stats-port $(CLUSTER_STATS_PORT)

test-cluster: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) UMBRA_VALIDATION=1 python3 tests/cluster/test_cluster.py

test-farm: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) UMBRA_VALIDATION=1 python3 tests/cluster/test_farm.py

bench-cluster: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) python3 tests/cluster/bench_cluster.py

bench-farm-remote: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) python3 tests/cluster/bench_farm.py 300 256

check-deploy:
	@sh deploy/check.sh

sizes:
	@python3 tests/sizes.py

print-version:
	@echo $(UMBRA_VERSION)

# libFuzzer targets (clang, ASan + UBSan; tests/fuzz/run.sh has the conventions): every
# tests/fuzz/fuzz_*.c becomes build/fuzz/fuzz_*, linked with the api, renderer and server
# (server/main.c with its main() renamed) libraries built with fuzzer instrumentation. Seeds:
# tests/fuzz/corpus/<name>/; optional <name>.dict and <name>.options next to the source.
#   make fuzz                      build them all
#   make fuzz-long FUZZ_RUNS=N  run each for FUZZ_RUNS executions, one at a time; prints a table
FUZZ_BUILD := build/fuzz
FUZZ_SRC := $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_SAN := -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_RUNS ?= 1000000
fuzz: deps
	@$(MAKE) --no-print-directory BUILD=$(FUZZ_BUILD) CC=clang CXX=clang++ OPT=-O1 SAN="$(FUZZ_SAN)" fuzz-targets

fuzz-long: fuzz
	@FUZZ_BUILD=$(FUZZ_BUILD) sh tests/fuzz/long.sh $(FUZZ_RUNS)

# Inside the sub-make above (BUILD = build/fuzz).
# The model-import targets go through the sandbox: umbra-import next to them.
fuzz-targets: $(FUZZ_SRC:tests/fuzz/%.c=$(BUILD)/%) $(BUILD)/umbra-import
# server/main.c goes in with its main() renamed: targets get srv_now() and the other helpers it
# defines, and libFuzzer keeps its own main().
$(BUILD)/obj/server/main_fuzz.o: server/main.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(INC_SERVER) -Dmain=srv_main_unused -c -o $@ $<
$(BUILD)/libsrv.a: $(filter-out $(BUILD)/obj/server/main.o,$(SRV_OBJ)) $(BUILD)/obj/server/main_fuzz.o
	@rm -f $@; ar rcs $@ $^
.PRECIOUS: $(BUILD)/obj/tests/fuzz/%.o
$(BUILD)/fuzz_%: $(BUILD)/obj/tests/fuzz/fuzz_%.o $(BUILD)/libsrv.a $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -fsanitize=fuzzer -o $@ $^ $(LIBS)

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
