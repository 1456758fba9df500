# Thin wrapper over CMake. `make render` and `make test` are README's two commands after
# scripts/install-deps.sh.
BUILD ?= build
JOBS ?= $(shell nproc)

.PHONY: deps build render test bench clean

deps:
	scripts/install-deps.sh

build:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# The main job: the 8 course scenes into out/ as EXR + PNG.
render: build
	$(BUILD)/pathlab --scene all -o 'out/{index}-{scene}.exr' -o 'out/{index}-{scene}.png'

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Benchmarks (several minutes each); they print Markdown tables.
bench: build
	$(BUILD)/bench/pathlab_bench direct

clean:
	rm -rf $(BUILD)
