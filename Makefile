# volscissors: the two commands a user needs are `make demo` and `make test`.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=
# ccache, where installed, makes rebuilds in several checkouts cheap; it changes no output.
CCACHE_FLAG := $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache,)

.PHONY: deps configure build demo test test-asan test-readers-asan fuzz bench clean install install-python

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CCACHE_FLAG) $(CMAKE_FLAGS) > $(BUILD).configure.log 2>&1 || (cat $(BUILD).configure.log; exit 1)

build: configure
	@cmake --build $(BUILD) -j $(JOBS) -- --no-print-directory

demo: build
	@scripts/demo.sh $(BUILD)

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-asan: export LSAN_OPTIONS = suppressions=$(CURDIR)/scripts/lsan.supp:print_suppressions=0
test-asan: export ASAN_OPTIONS = detect_leaks=1
test-asan:
	@$(MAKE) --no-print-directory test BUILD=build-asan CMAKE_FLAGS="-DVS_SANITIZE=ON -DVS_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo"

# Only the readers under ASan+UBSan (what CI runs): test_io and the fuzz targets' corpus replayed
# without libFuzzer, in build-asan/ (shared with test-asan). A few minutes on 2 cores.
test-readers-asan: build
	@JOBS=$(JOBS) scripts/asan-readers.sh

# libFuzzer targets (clang, build-fuzz/), a seed corpus from `volscissors phantom` and a bounded
# run of every reader: FUZZ_SECONDS per target (default 5). Crashes land in build-fuzz/fuzz-crashes/.
fuzz: build
	@scripts/fuzz.sh

# The core library (libvolscissors, headers, CMake package volscissors::core, pkg-config volscissors)
# and the CLI into PREFIX (default /usr/local; e.g. make install PREFIX=$$HOME/.local).
PREFIX ?= /usr/local
install: build
	@cmake --install $(BUILD) --prefix $(PREFIX)

# The Python package (build/python/volscissors) into the user's site-packages of Debian's python3.
install-python: build
	@site=$$(/usr/bin/python3 -m site --user-site) && mkdir -p "$$site" && rm -rf "$$site/volscissors" && \
	  cp -r $(BUILD)/python/volscissors "$$site/" && rm -rf "$$site/volscissors/__pycache__" && \
	  echo "installed volscissors into $$site (import volscissors with /usr/bin/python3)"

bench: build
	@scripts/bench.sh $(BUILD)

clean:
	rm -rf build build-asan build-fuzz build.configure.log build-asan.configure.log build-fuzz.configure.log
