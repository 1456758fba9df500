// Bad usage: a request that names something that does not exist or gives an invalid value
// (unknown scene, algorithm or option, a malformed scene file). The command line reports it
// with exit code 2.
#pragma once

#include <stdexcept>

namespace pathlab {

struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

}  // namespace pathlab
