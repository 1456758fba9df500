// Runs pathlab's command line in-process and captures what it prints, for the CLI tests.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "app/cli.hpp"

namespace pathlab::test {

struct CliResult {
    int code;
    std::string out, err;
};

// `args` without the program name.
inline CliResult run(std::vector<std::string> args) {
    args.insert(args.begin(), "pathlab");
    std::vector<const char*> argv;
    for (const std::string& a : args) argv.push_back(a.c_str());
    testing::internal::CaptureStdout();
    testing::internal::CaptureStderr();
    const int code = run_cli(int(argv.size()), argv.data());
    std::string out = testing::internal::GetCapturedStdout();
    std::string err = testing::internal::GetCapturedStderr();
    return {code, out, err};
}

inline bool contains(const std::string& s, const std::string& needle) { return s.find(needle) != std::string::npos; }

}  // namespace pathlab::test
