// The pathlab command line. Exit codes: 0 success, 1 failure while working (I/O, scene
// build), 2 bad usage (unknown option, scene or algorithm; invalid value), 130 interrupted
// (the image so far was still written).
#pragma once

namespace pathlab {

class RankGroup;

// `ranks`: the processes of an MPI job this one belongs to (app/main.cpp), null when alone. Only
// the render command runs across processes; the others refuse to (exit code 2). `resuming`: the
// arguments are a checkpoint's command continued (app/resumed_command.hpp), not the user's own.
int run_cli(int argc, const char* const* argv, RankGroup* ranks = nullptr, bool resuming = false);

}  // namespace pathlab
