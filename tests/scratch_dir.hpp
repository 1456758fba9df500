// A fresh folder of its own under the system's temporary directory (mkdtemp, so tests running
// at once never share one), removed with everything in it when the object goes.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace pathlab::test {

struct ScratchDir {
    std::string path;
    explicit ScratchDir(const std::string& prefix) {
        std::string p = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
        if (!mkdtemp(p.data())) throw std::runtime_error("cannot make a temporary folder " + p);
        path = p;
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
};

}  // namespace pathlab::test
