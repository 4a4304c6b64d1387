#include "Subcommand.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"

namespace rubble::tools {

std::vector<Subcommand>& registry() {
    static std::vector<Subcommand> all;
    return all;
}

CLI::Validator finiteNumber() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            double v = 0;
            const char* first = text.data() + (!text.empty() && text[0] == '+' ? 1 : 0);
            const auto [ptr, ec] = std::from_chars(first, text.data() + text.size(), v);
            if (ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v))
                return "'" + text + "' is not a finite number";
            return {};
        },
        "FINITE");
}

CLI::Validator unsigned64() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            std::uint64_t v = 0;
            const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
            if (text.empty() || ec != std::errc() || ptr != text.data() + text.size())
                return "'" + text + "' is not a whole number from 0 to 18446744073709551615";
            return {};
        },
        "UINT64");
}

int runMain(const std::string& description, const std::string& version, int argc, char** argv) {
    CLI::App app{description};
    app.require_subcommand(1);
    app.set_version_flag("--version", version);
    auto& all = registry();
    std::sort(all.begin(), all.end(),
              [](const Subcommand& a, const Subcommand& b) { return a.name < b.name; });
    std::vector<std::function<int()>> runners(all.size());
    std::vector<CLI::App*> subs;
    for (std::size_t i = 0; i < all.size(); ++i) {
        CLI::App* sub = app.add_subcommand(all[i].name, all[i].description);
        runners[i] = all[i].setup(*sub);
        subs.push_back(sub);
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // Help and version exit 0; usage errors exit 2 (with --json, also as {"error"} on stdout).
        const int code = app.exit(e);
        if (code != 0 &&
            std::any_of(argv + 1, argv + argc, [](const char* a) { return a == std::string("--json"); }))
            std::cout << dumpJson(nlohmann::json{{"error", utf8Escaped(e.what())}}) << "\n";
        return code == 0 ? 0 : 2;
    }
    for (std::size_t i = 0; i < subs.size(); ++i)
        if (subs[i]->parsed())
            return runners[i]();
    return 2;
}

} // namespace rubble::tools
