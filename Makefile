# scanplan: `make demo` and `make test` are the two commands a fresh Debian bookworm machine needs.
BUILD ?= build
JOBS ?= 2
PORT ?= 8080
ROBOTS ?= 1
WEB_SOURCES := $(wildcard web/src/*) web/index.html web/build.mjs web/package.json

# In CI (CI set in the environment) warnings are errors.
CMAKE_FLAGS := -DCMAKE_BUILD_TYPE=Release $(if $(CI),-DSCANPLAN_WERROR=ON,-DSCANPLAN_WERROR=OFF)

.PHONY: all deps web build test demo format check-sanitizers fuzz clean

all: build

deps:
	@scripts/install-deps.sh

# npm ci only when the lock file changed since the last install.
web/node_modules/.scanplan-installed: web/package-lock.json web/package.json
	cd web && npm ci --no-audit --no-fund --loglevel=error
	@touch $@

web/dist/index.html: web/node_modules/.scanplan-installed $(WEB_SOURCES)
	cd web && npm run --silent build

web: deps web/dist/index.html

build: deps web
	cmake -S . -B $(BUILD) $(CMAKE_FLAGS)
	cmake --build $(BUILD) -j$(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

demo: build
	ROBOTS=$(ROBOTS) scripts/demo.sh $(BUILD) $(PORT)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

# Unit and integration tests under ASan+UBSan, then TSan (build-asan/, build-tsan/); not part of
# make test. Time on the 2-core machine: docs/architecture.md.
check-sanitizers: deps web
	JOBS=$(JOBS) scripts/check-sanitizers.sh

# The fuzz targets under libFuzzer with ASan+UBSan (build-fuzz/), FUZZ_SECONDS each (default 120);
# not part of make test, which replays their corpora. Figures: docs/architecture.md.
fuzz: deps
	JOBS=$(JOBS) scripts/fuzz.sh

clean:
	rm -rf $(BUILD) build-asan build-tsan build-fuzz web/dist
