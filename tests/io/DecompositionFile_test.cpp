// The decomposition file beside an asset: exact round trip, errors that name the file and the field.
#include <fstream>

#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "rubble/io/DecompositionFile.hpp"

namespace rubble {
namespace {

void writeText(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

TEST(DecompositionFile, RoundTripIsExact) {
    const auto dir = test::tempDir("decomposition_file");
    DecompositionFile f;
    f.meshHash = 0x0123456789abcdefull;
    f.meshVolume = 1.0 / 3.0;
    f.parts.push_back(ConvexPolytope::fromAabb({{0.1, 0.2, 0.3}, {1.0 / 7, 2, 3}})
                          .clipped(Plane::fromPointNormal({0.1, 1, 1}, {1, 1, 0.3})));
    f.parts.push_back(ConvexPolytope::fromAabb({{-1, -1, -1}, {0, 0, 0}}));
    const auto path = dir / "thing.parts.json";
    ASSERT_TRUE(writeDecompositionFile(path, f));
    auto back = readDecompositionFile(path);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->meshHash, f.meshHash);
    EXPECT_EQ(back->meshVolume, f.meshVolume);
    ASSERT_EQ(back->parts.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        ASSERT_EQ(back->parts[i].faces().size(), f.parts[i].faces().size());
        for (std::size_t k = 0; k < f.parts[i].faces().size(); ++k) {
            EXPECT_EQ(back->parts[i].faceList()[k].corners, f.parts[i].faceList()[k].corners);
            EXPECT_EQ(back->parts[i].faces()[k].plane.offset, f.parts[i].faces()[k].plane.offset);
        }
    }
    EXPECT_EQ(decompositionPathFor("a/b/arch.obj"), std::filesystem::path("a/b/arch.parts.json"));
}

TEST(DecompositionFile, ErrorsNameTheFileAndTheField) {
    const auto dir = test::tempDir("decomposition_file_bad");
    const auto path = dir / "bad.parts.json";
    const std::string head =
        R"({"format":"rubble-decomposition","version":1,"mesh_hash":"00000000000000ff",)";
    struct Case {
        std::string text, expect;
    };
    const std::vector<Case> cases = {
        {"{\"format\":", "byte"},
        {R"({"format":"other","version":1})", "format"},
        {R"({"format":"rubble-decomposition","version":3})", "version"},
        {R"({"format":"rubble-decomposition","version":1,"mesh_hash":"xyz"})", "mesh_hash"},
        {head + R"("mesh_volume":"big","parts":[]})", "mesh_volume"},
        {head + R"("mesh_volume":1,"parts":[{"faces":[{"normal":[1,0],"offset":0,"corners":[]}]}]})",
         "parts[0].faces[0].normal"},
        {head + R"("mesh_volume":1,"parts":[{"faces":[]}]})", "parts[0]: not a solid"},
    };
    for (const Case& c : cases) {
        writeText(path, c.text);
        auto r = readDecompositionFile(path);
        ASSERT_FALSE(r) << c.text;
        EXPECT_EQ(r.error().code, ErrorCode::ParseError) << c.text;
        EXPECT_NE(r.error().message.find("bad.parts.json"), std::string::npos) << r.error().message;
        EXPECT_NE(r.error().message.find(c.expect), std::string::npos) << r.error().message;
    }
    EXPECT_EQ(readDecompositionFile(dir / "missing.parts.json").error().code, ErrorCode::IoError);
}

} // namespace
} // namespace rubble
