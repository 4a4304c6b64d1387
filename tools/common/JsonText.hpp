#pragma once
// Text for the CLI tools' JSON output: nlohmann's dump() throws (and an uncaught throw aborts) on bytes that
// are not UTF-8, which file names and messages quoting a file's bytes may hold.

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace rubble::tools {

/// text with every byte that is not part of well-formed UTF-8 written as the four characters \xHH (as the
/// scene reader shows control bytes), so that any path or message can go into JSON.
std::string utf8Escaped(std::string_view text);

/// doc.dump(indent) that never throws: strings should be utf8Escaped already; any invalid byte left is
/// replaced by U+FFFD.
std::string dumpJson(const nlohmann::json& doc, int indent = -1);

} // namespace rubble::tools
