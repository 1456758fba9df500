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

# The main job: the 8 course scenes into out/ as EXR + PNG. Direct illumination by direct-mis (the
# course's assignments 1-3) at the scenes' 512x512 and 64 spp; global illumination (assignment 4)
# by pt-mis at 256x256 and 1024 spp, README's pictures of the global set (fewer samples leave the
# glossy scenes speckled with fireflies).
render: build
	$(BUILD)/pathlab all --algorithm direct-mis -o 'out/direct/{index}-{scene}.exr' -o 'out/direct/{index}-{scene}.png'
	$(BUILD)/pathlab all --algorithm pt-mis --resolution 256x256 --spp 1024 -o 'out/global/{index}-{scene}.exr' -o 'out/global/{index}-{scene}.png'

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# The performance suite (about 7 minutes on a quiet 2-core machine): throughput, scaling, Embree's bound, scene growth,
# memory, allocations and pt-mis efficiency; Markdown on stdout, JSON in out/bench/; then light tracing (lt paths/s
# next to pt-mis, splat accumulation, 1 minute), bdpt against pt-mis (12 minutes), pt-mis, bdpt, bpm and vcm on SmallVCM's kind of
# scene at 512x512 (time per iteration, MSE per sample, efficiency: 10 minutes), the photon methods (10 minutes), irradiance caching (13 minutes),
# rendering across processes (2 MPI ranks against 1 process, film reduction, checkpoints: 3 minutes), the lights (an environment map's cost
# per sample against the constant environment, spot and IES: 2 minutes), the light samplers
# (uniform, power and the light BVH at equal time on the many-light scenes and the course scenes: 6 minutes), volpath (volumes: throughput, MIS at equal time, optical thickness),
# textures (textured against constant materials per sample, texture lookups: 2 minutes) and differentiable rendering (a gradient against a
# primal render, memory vs spp and depth: 1 minute) and streaming to a viewer (--display-server's cost: 1.5 minutes).
bench: build
	$(BUILD)/bench/pathlab_bench perf --json out/bench/performance.json
	$(BUILD)/bench/pathlab_bench lt
	$(BUILD)/bench/pathlab_bench bdpt
	$(BUILD)/bench/pathlab_bench bidir
	$(BUILD)/bench/pathlab_bench pm
	$(BUILD)/bench/pathlab_bench ic
	$(BUILD)/bench/pathlab_bench distributed
	$(BUILD)/bench/pathlab_bench lights
	$(BUILD)/bench/pathlab_bench many-lights
	$(BUILD)/bench/pathlab_bench volumes
	$(BUILD)/bench/pathlab_bench textures
	$(BUILD)/bench/pathlab_bench diff
	$(BUILD)/bench/pathlab_bench display

# Equal-spp and equal-time RMSE of the course's estimators on the 8 scenes (about 10 minutes).
bench-estimators: build
	$(BUILD)/bench/pathlab_bench direct
	$(BUILD)/bench/pathlab_bench pt

clean:
	rm -rf $(BUILD)
