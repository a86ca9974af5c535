# Entry points. Every target installs what is missing and builds first.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?= -DCMAKE_BUILD_TYPE=RelWithDebInfo

.PHONY: all deps configure build test test-asan test-asan-ci fuzz demo bench format format-check clean

all: build

deps:
	./scripts/install-deps.sh

configure: deps
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)

build: configure
	cmake --build $(BUILD) -j $(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The whole suite built with AddressSanitizer and UndefinedBehaviorSanitizer (its own build directory),
# undefined behaviour fatal.
ASAN_BUILD ?= build-asan
test-asan: deps
	cmake -S . -B $(ASAN_BUILD) $(CMAKE_FLAGS) -DFRAC_SANITIZE=ON
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS)

# CI's share of the sanitizer run (CI has 90 minutes on a 2-core machine, and the whole instrumented suite
# does not fit beside the normal one): every layer through `frac` — the golden language tests (frontend,
# lowering, interpreter, JIT, AOT, runtime, driver, CLI), the hostile catalogue, killed runs, the docs'
# and examples' blocks — and the unit tests of support, numeric, ir, frontend and the interpreter. The
# JIT's cross-checks, the runtime's unit tests and the soundness suites run in `make test-asan`.
# Its own build directory at -O1 with line tables only: instrumented -O2 -g code takes 2.4 times as long
# to compile (runtime/automata/chaos.cpp: 174 s against 72 s).
ASAN_CI_BUILD ?= build-asan-ci
ASAN_CI_TARGETS = frac lang_runner unit_support unit_numeric unit_ir unit_frontend unit_interp
ASAN_CI_TESTS = ^(lang|cli|robustness|docs|examples|support|numeric|ir|frontend|interp):
test-asan-ci: deps
	cmake -S . -B $(ASAN_CI_BUILD) $(CMAKE_FLAGS) -DFRAC_SANITIZE=ON \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo '-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG'
	cmake --build $(ASAN_CI_BUILD) -j $(JOBS) --target $(ASAN_CI_TARGETS)
	cd $(ASAN_CI_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -R '$(ASAN_CI_TESTS)'

# libFuzzer targets built with clang-19 (installed on demand), each run FUZZ_SECONDS with a seed corpus
# from tests/lang and stdlib (tests/fuzz/run.sh); findings go to $(FUZZ_BUILD)/findings.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 120
fuzz: deps
	./scripts/install-deps.sh --fuzz
	CC=clang-19 CXX=clang++-19 cmake -S . -B $(FUZZ_BUILD) $(CMAKE_FLAGS) -DFRAC_FUZZ=ON
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzz_frontend fuzz_eval
	./tests/fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

demo: build
	./examples/render-all.sh $(BUILD)/frac $(BUILD)/demo

bench: build
	cmake --build $(BUILD) -j $(JOBS) --target bench_all

# Every tracked C++ file, formatted by .clang-format; format-check changes nothing and fails on a diff.
format:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run --Werror

clean:
	rm -rf $(BUILD)
