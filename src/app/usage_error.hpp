// Bad command-line usage (unknown name, invalid value): reported with exit code 2.
#pragma once

#include <stdexcept>

namespace pathlab {

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace pathlab
