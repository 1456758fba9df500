// The pathlab command line. Exit codes: 0 success, 1 failure while working (I/O, scene
// build), 2 bad usage (unknown option, scene or algorithm; invalid value), 130 interrupted
// (the image so far was still written).
#pragma once

namespace pathlab {

int run_cli(int argc, const char* const* argv);

}  // namespace pathlab
