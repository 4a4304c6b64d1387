#include "JsonText.hpp"

#include <gtest/gtest.h>

#include "rubble/io/MeshIO.hpp"

using rubble::tools::dumpJson;
using rubble::tools::utf8Escaped;

TEST(JsonText, ValidUtf8IsKeptByteForByte) {
    const std::string text = "caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80 plain/ascii.obj";
    EXPECT_EQ(utf8Escaped(text), text);
    EXPECT_EQ(utf8Escaped(""), "");
}

TEST(JsonText, InvalidBytesBecomeHexEscapes) {
    EXPECT_EQ(utf8Escaped("v 0 1 \xE9"), "v 0 1 \\xE9");                // Latin-1 byte
    EXPECT_EQ(utf8Escaped("\xC3"), "\\xC3");                            // truncated sequence
    EXPECT_EQ(utf8Escaped("\xC0\xAF"), "\\xC0\\xAF");                   // overlong '/'
    EXPECT_EQ(utf8Escaped("\xED\xA0\x80"), "\\xED\\xA0\\x80");          // surrogate U+D800
    EXPECT_EQ(utf8Escaped("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80"); // above U+10FFFF
    EXPECT_EQ(utf8Escaped("\xFF"
                          "a\xC3\xA9"),
              "\\xFFa\xC3\xA9");
}

TEST(JsonText, DumpingEscapedTextNeverThrowsAndParsesBack) {
    const std::string path = "dir\xE9/m\xFF\xFE.obj";
    auto mesh = rubble::parseObj("v 0 1 \xE9\n", path);
    ASSERT_FALSE(mesh);
    nlohmann::json doc = {{"file", utf8Escaped(path)}, {"error", utf8Escaped(mesh.error().message)}};
    std::string text;
    ASSERT_NO_THROW(text = doc.dump()); // strict dump: it would throw on any invalid byte
    const auto back = nlohmann::json::parse(text);
    EXPECT_EQ(back["file"], "dir\\xE9/m\\xFF\\xFE.obj");
    EXPECT_NE(back["error"].get<std::string>().find("got '\\xE9'"), std::string::npos) << text;
    // The safety net: unescaped invalid bytes are replaced instead of throwing.
    EXPECT_EQ(dumpJson(nlohmann::json{{"f", "a\xE9"}}), "{\"f\":\"a\xEF\xBF\xBD\"}");
}
