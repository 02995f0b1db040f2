# umbra — one non-recursive Makefile.
#   make            build/librenderer.a, build/umbra-render, build/umbrad
#   make run        install deps, build, start umbrad on 127.0.0.1:8080
#   make test       install deps, build, run every test (last line: "N passed, N failed")
#   make test-asan  the same suite built with AddressSanitizer + UBSan
#   make bench      warm-process and HTTP benchmarks of ../shared/bench
#   make soak       10,000 mixed requests against one umbrad; RSS and descriptors must stay flat
BUILD ?= build
SHARED ?= ../shared
CC ?= cc
GLSLANG ?= glslangValidator
PKGS := vulkan jansson libmicrohttpd libpng OpenEXR zlib assimp libjpeg

OPT ?= -O2
SAN ?=
CFLAGS ?= $(OPT) -g
CFLAGS += -std=c11 -D_GNU_SOURCE -Wall -Wextra -Werror -Wno-missing-field-initializers \
          -fno-strict-aliasing -pthread -MMD -MP $(SAN) \
          -Irenderer/include -Irenderer -Ishaders -Iapi -Iserver -I$(BUILD)/shaders
LDFLAGS += -pthread $(SAN)
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS := $(shell pkg-config --libs $(PKGS) 2>/dev/null)
CFLAGS += $(PKG_CFLAGS)
# The build's version (in /v1/info and the ETag): the commit, "-dirty" with local changes.
UMBRA_VERSION := $(shell git describe --always --dirty 2>/dev/null || echo unknown)
CFLAGS += -DUMBRA_VERSION=\"$(UMBRA_VERSION)\"
LIBS := $(PKG_LIBS) -lm

RND_SRC := $(wildcard renderer/*.c)
API_SRC := $(wildcard api/*.c)
SRV_SRC := $(filter-out server/cli.c,$(wildcard server/*.c))
UNIT_SRC := $(wildcard tests/unit/*.c)
GPU_SRC := $(wildcard tests/gpu/*.c)
SHADERS := $(wildcard shaders/*.vert shaders/*.frag shaders/*.comp)
SHADER_HDRS := $(patsubst shaders/%,$(BUILD)/shaders/%.spv.h,$(SHADERS))

RND_OBJ := $(RND_SRC:%.c=$(BUILD)/obj/%.o)
API_OBJ := $(API_SRC:%.c=$(BUILD)/obj/%.o)
SRV_OBJ := $(SRV_SRC:%.c=$(BUILD)/obj/%.o)
UNIT_OBJ := $(UNIT_SRC:%.c=$(BUILD)/obj/%.o)
GPU_OBJ := $(GPU_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/tests/unit/test_main.o

BINS := $(BUILD)/librenderer.a $(BUILD)/libapi.a $(BUILD)/umbra-render $(BUILD)/tests/unit_tests
ifneq ($(SRV_SRC),)
BINS += $(BUILD)/umbrad
endif
ifneq ($(GPU_SRC),)
BINS += $(BUILD)/tests/gpu_tests
endif

.PHONY: all deps run test test-asan bench fuzz soak clean
all: $(BINS)

deps:
	@sh deploy/install-deps.sh

# Shaders: SPIR-V embedded as C arrays (spv_<file>_<stage>).
$(BUILD)/shaders/%.spv.h: shaders/% $(wildcard shaders/*.h shaders/*.glsl) | $(BUILD)/shaders
	$(GLSLANG) -V --target-env vulkan1.2 -Ishaders --vn spv_$(subst .,_,$*) -o $@ $< >/dev/null || \
	  { $(GLSLANG) -V --target-env vulkan1.2 -Ishaders -o /dev/null $<; exit 1; }
$(BUILD)/shaders:
	@mkdir -p $@

$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c -o $@ $<
# The renderer embeds the SPIR-V headers.
$(RND_OBJ): $(SHADER_HDRS)

$(BUILD)/librenderer.a: $(RND_OBJ)
	@rm -f $@; ar rcs $@ $^
$(BUILD)/libapi.a: $(API_OBJ)
	@rm -f $@; ar rcs $@ $^

$(BUILD)/umbra-render: $(BUILD)/obj/server/cli.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/umbrad: $(SRV_OBJ) $(BUILD)/libapi.a $(BUILD)/librenderer.a
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/unit_tests: $(UNIT_OBJ) $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/gpu_tests: $(GPU_OBJ) $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)

run: deps
	@$(MAKE) --no-print-directory all
	$(BUILD)/umbrad --listen 127.0.0.1:8080

test: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) SHARED=$(SHARED) sh tests/run.sh

test-asan: deps
	@$(MAKE) --no-print-directory BUILD=build/asan OPT=-O1 \
	  SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" all
	@BUILD=build/asan SHARED=$(SHARED) ASAN=1 sh tests/run.sh

# tests/run.sh runs a 1,000-request soak; this is the full one (SOAK_N=N for another size).
soak: deps
	@$(MAKE) --no-print-directory all
	@BUILD=$(BUILD) UMBRA_VALIDATION=1 sh tests/http/soak.sh

bench: deps
	@$(MAKE) --no-print-directory all $(BUILD)/tests/bench $(BUILD)/tests/http_bench
	@BUILD=$(BUILD) SHARED=$(SHARED) sh tests/bench.sh

$(BUILD)/tests/bench: $(BUILD)/obj/tests/bench/bench.o $(BUILD)/libapi.a $(BUILD)/librenderer.a
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/tests/http_bench: $(BUILD)/obj/tests/bench/http_bench.o
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^

# libFuzzer target for the scene parser (clang): build/fuzz/fuzz_scene tests/fuzz/corpus
fuzz:
	@$(MAKE) --no-print-directory BUILD=build/fuzz CC=clang OPT=-O1 \
	  SAN="-fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer" build/fuzz/libapi.a build/fuzz/librenderer.a
	clang -O1 -g -fsanitize=fuzzer,address,undefined -Iapi -Irenderer/include $(PKG_CFLAGS) \
	  -o build/fuzz/fuzz_scene tests/fuzz/fuzz_scene.c build/fuzz/libapi.a build/fuzz/librenderer.a $(LIBS)

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
