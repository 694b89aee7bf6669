# scanplan: `make demo` and `make test` are the two commands a fresh Debian bookworm machine needs.
BUILD ?= build
JOBS ?= 2
PORT ?= 8080
ROBOTS ?= 1
WEB_SOURCES := $(wildcard web/src/*) web/index.html web/build.mjs web/package.json

.PHONY: all deps web build test demo format clean

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
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j$(JOBS)

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

demo: build
	ROBOTS=$(ROBOTS) scripts/demo.sh $(BUILD) $(PORT)

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) web/dist
