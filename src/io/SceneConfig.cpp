#include "rubble/io/SceneConfig.hpp"

#include "rubble/core/ParameterCheck.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "io/FileBytes.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/structure/Material.hpp"

namespace rubble {

namespace {
constexpr const char* kFieldNames[11] = {"model", "texture", "x",    "y",        "z",        "sx",
                                         "sy",    "sz",      "mass", "material", "roughness"};
constexpr const char* kOrdinals[11] = {"1st", "2nd", "3rd", "4th",  "5th", "6th",
                                       "7th", "8th", "9th", "10th", "11th"};
constexpr const char* kSkyboxNames[6] = {"top", "bottom", "left", "right", "front", "back"};

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
        s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
        s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> splitFields(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= line.size(); ++i)
        if (i == line.size() || line[i] == ';') {
            out.push_back(trim(line.substr(start, i - start)));
            start = i + 1;
        }
    // One trailing ';' (an empty last field) is tolerated.
    if (out.size() > 1 && out.back().empty())
        out.pop_back();
    return out;
}

std::string shown(std::string_view s) {
    std::string out;
    for (char c : s.substr(0, 40)) {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7F) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02X", u);
            out += buf;
        } else {
            out += c;
        }
    }
    return s.size() > 40 ? out + "..." : out;
}

class Parser {
public:
    Parser(std::string name, std::filesystem::path base) : name_(std::move(name)) {
        cfg_.baseDir = std::move(base);
    }

    Result<SceneConfig> run(std::string_view text) {
        if (text.substr(0, 3) == "\xEF\xBB\xBF")
            text.remove_prefix(3);
        std::size_t pos = 0, lineNo = 0, entity = 0;
        while (pos <= text.size()) {
            ++lineNo;
            std::size_t end = text.find('\n', pos);
            if (end == std::string_view::npos)
                end = text.size();
            std::string_view line = text.substr(pos, end - pos);
            pos = end + 1;
            if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
                line = line.substr(0, hash);
            line = trim(line);
            if (line.empty())
                continue;
            line_ = lineNo;
            Status s = entity == 0 ? skybox(line) : object(line, entity);
            if (!s)
                return s.error();
            ++entity;
        }
        if (entity < 3) {
            static const char* const what[3] = {"the skybox line (line 1)", "the ground line (line 2)",
                                                "the vehicle line (line 3)"};
            return makeError(ErrorCode::ParseError,
                             name_ + ": missing " + what[entity] +
                                 "; a scene file needs a skybox, a ground and a vehicle line");
        }
        return std::move(cfg_);
    }

private:
    std::string where() const { return name_ + ":" + std::to_string(line_) + ": "; }

    Error fail(const std::string& message) const {
        return makeError(ErrorCode::ParseError, where() + message);
    }

    std::filesystem::path resolve(std::string_view name) const {
        const std::filesystem::path p{std::string(name)};
        return p.is_absolute() ? p : cfg_.baseDir / p;
    }

    bool exists(const std::filesystem::path& p) const {
        std::error_code ec;
        return std::filesystem::is_regular_file(p, ec);
    }

    void warn(const std::string& message) { cfg_.warnings.push_back({line_, where() + message}); }

    Status skybox(std::string_view line) {
        const auto f = splitFields(line);
        if (f.size() != 6)
            return fail(
                "expected 6 skybox images separated by ';' (top, bottom, left, right, front, back), got " +
                std::to_string(f.size()) + (f.size() == 1 ? " field" : " fields"));
        for (std::size_t i = 0; i < 6; ++i) {
            if (f[i].empty())
                return fail("skybox image " + std::to_string(i + 1) + " (" + kSkyboxNames[i] + ") is empty");
            cfg_.skybox[i] = std::string(f[i]);
            cfg_.skyboxPaths[i] = resolve(f[i]);
            if (!exists(cfg_.skyboxPaths[i]))
                warn("skybox image '" + cfg_.skybox[i] + "' not found");
        }
        return {};
    }

    Status number(std::string_view text, std::size_t field, double& out) {
        const std::string prefix =
            std::string("field '") + kFieldNames[field] + "' (" + kOrdinals[field] + "): ";
        std::string_view s = text;
        if (!s.empty() && s.front() == '+')
            s.remove_prefix(1);
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
        if (s.empty() || s.front() == '+' || ptr != s.data() + s.size() || ec == std::errc::invalid_argument)
            return fail(prefix + "expected a number, got '" + shown(text) + "'");
        if (ec == std::errc::result_out_of_range || !std::isfinite(out))
            return fail(prefix + "expected a finite number, got '" + shown(text) + "'");
        return {};
    }

    Status object(std::string_view line, std::size_t entity) {
        const auto f = splitFields(line);
        const char* role = entity == 1 ? "ground" : entity == 2 ? "vehicle" : "object";
        if (f.size() < 9 || f.size() > 11)
            return fail(std::string("expected 9 to 11 fields for the ") + role +
                        " (model;texture;x;y;z;sx;sy;sz;mass[;material[;roughness]]), got " +
                        std::to_string(f.size()));
        SceneObject o;
        o.line = line_;
        o.model = std::string(f[0]);
        o.texture = std::string(f[1]);
        double v[7];
        for (std::size_t i = 0; i < 7; ++i)
            if (Status s = number(f[i + 2], i + 2, v[i]); !s)
                return s;
        o.position = {v[0], v[1], v[2]};
        o.scale = {v[3], v[4], v[5]};
        o.mass = v[6];
        for (std::size_t i = 0; i < 3; ++i)
            if (o.scale[static_cast<int>(i)] == 0)
                return fail(std::string("field '") + kFieldNames[i + 5] + "' (" + kOrdinals[i + 5] +
                            "): scale must not be 0");
        if (o.mass < 0)
            return fail("field 'mass' (9th): mass must not be negative, got '" + shown(f[8]) + "'");
        if (f.size() == 11) {
            double amplitude = 0;
            if (f[10] != "flat" && (!number(f[10], 10, amplitude) || !checkParam("roughness", amplitude)))
                return fail("field 'roughness' (11th): expected 'flat' or " +
                            describeParamRange(*findParamRange("roughness")) +
                            " (the amplitude relative to the cell size), got '" + shown(f[10]) + "'");
            o.roughness = amplitude;
        }
        if (f.size() >= 10 && !(f.size() == 11 && f[9].empty())) {
            if (!findMaterial(f[9]))
                return fail("field 'material' (10th): unknown material '" + shown(f[9]) +
                            "'; expected one of " + materialNames());
            o.material = std::string(f[9]);
        }
        if (!o.model.empty()) {
            o.modelPath = resolve(o.model);
            o.modelFound = exists(o.modelPath);
            if (!o.modelFound)
                warn("model '" + o.model + "' not found");
        } else if (entity != 1) {
            warn(std::string("the ") + role + " has no model");
        }
        if (!o.texture.empty()) {
            o.texturePath = resolve(o.texture);
            o.textureFound = exists(o.texturePath);
            if (!o.textureFound)
                warn("texture '" + o.texture + "' not found");
        }
        if (entity == 1)
            cfg_.ground = std::move(o);
        else if (entity == 2)
            cfg_.vehicle = std::move(o);
        else
            cfg_.objects.push_back(std::move(o));
        return {};
    }

    std::string name_;
    std::size_t line_ = 0;
    SceneConfig cfg_;
};
} // namespace

Result<SceneConfig> parseSceneConfigText(const std::string& text, const std::string& displayName,
                                         const std::filesystem::path& baseDir) {
    std::filesystem::path base = baseDir;
    if (base.empty())
        base = std::filesystem::path(displayName).parent_path();
    return Parser(displayName, base).run(text);
}

Result<SceneConfig> parseSceneConfig(const std::filesystem::path& path) {
    auto bytes = io::readFileBytes(path);
    if (!bytes)
        return bytes.error();
    return parseSceneConfigText(bytes.value(), io::displayName(path), path.parent_path());
}

} // namespace rubble
