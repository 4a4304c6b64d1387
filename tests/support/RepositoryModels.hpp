#pragma once
// The repository's models (assets/models/*.obj) as named meshes, for tests that sweep over shapes. Header
// only: the tests that include it link rubble_io.

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "rubble/io/MeshIO.hpp"

namespace rubble::test {

/// A mesh with a name for failure messages.
struct NamedMesh {
    std::string name;
    Mesh mesh;
};

/// Appends assets/models/<name>.obj for every name to shapes (an unreadable model is a test failure).
inline void appendRepositoryModels(std::vector<NamedMesh>& shapes, std::initializer_list<const char*> names) {
    for (const char* name : names) {
        auto m = readObj(sourceDir() / "assets" / "models" / (std::string(name) + ".obj"));
        EXPECT_TRUE(m.isOk()) << name << ": " << (m ? "" : m.error().message);
        if (m)
            shapes.push_back({name, std::move(*m)});
    }
}

} // namespace rubble::test
