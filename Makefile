# Thin wrapper over CMake. `make render` and `make test` are README's two commands after
# scripts/install-deps.sh.
BUILD ?= build
JOBS ?= $(shell nproc)

.PHONY: deps build render test bench bench-estimators clean

deps:
	scripts/install-deps.sh

build:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# The main job: the 8 course scenes into out/ as EXR + PNG, with direct illumination (the
# course's assignments 1-3) and with global illumination (assignment 4).
render: build
	$(BUILD)/pathlab --scene all --algorithm direct-light -o 'out/direct/{index}-{scene}.exr' -o 'out/direct/{index}-{scene}.png'
	$(BUILD)/pathlab --scene all --algorithm pt-mis -o 'out/global/{index}-{scene}.exr' -o 'out/global/{index}-{scene}.png'

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The performance suite (about 7 minutes on a quiet 2-core machine): throughput, scaling, Embree's bound, scene growth,
# memory, allocations and pt-mis efficiency; Markdown on stdout, JSON in out/bench/; then light tracing (lt paths/s
# next to pt-mis, splat accumulation, 1 minute), bdpt against pt-mis (12 minutes), the photon methods (10 minutes), irradiance caching (13 minutes),
# rendering across processes (2 MPI ranks against 1 process, film reduction, checkpoints: 3 minutes) and the lights (an environment map's cost
# per sample against the constant environment, spot and IES: 2 minutes).
bench: build
	$(BUILD)/bench/pathlab_bench perf --json out/bench/performance.json
	$(BUILD)/bench/pathlab_bench lt
	$(BUILD)/bench/pathlab_bench bdpt
	$(BUILD)/bench/pathlab_bench pm
	$(BUILD)/bench/pathlab_bench ic
	$(BUILD)/bench/pathlab_bench distributed
	$(BUILD)/bench/pathlab_bench lights

# Equal-spp and equal-time RMSE of the course's estimators on the 8 scenes (about 10 minutes).
bench-estimators: build
	$(BUILD)/bench/pathlab_bench direct
	$(BUILD)/bench/pathlab_bench pt

clean:
	rm -rf $(BUILD)
