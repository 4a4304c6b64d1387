#include "rubble/structure/Material.hpp"

namespace rubble {

const std::vector<Material>& materialPresets() {
    // Characteristic values; sources per row in docs/structure.md.
    static const std::vector<Material> presets = {
        {"concrete", 2400, 30, 2.9, 6.0, FracturePattern::Clustered},
        {"brick", 1900, 9, 0.4, 0.3, FracturePattern::Clustered},
        {"stone", 2700, 150, 10, 25, FracturePattern::Clustered},
        {"wood", 420, 21, 14.5, 4.0, FracturePattern::Splinter},
        {"glass", 2500, 1000, 45, 45, FracturePattern::Radial},
        {"steel", 7850, 355, 355, 205, FracturePattern::Uniform},
    };
    return presets;
}

const Material* findMaterial(std::string_view name) {
    for (const Material& m : materialPresets())
        if (m.name == name)
            return &m;
    return nullptr;
}

const Material& defaultMaterial() {
    return materialPresets().front();
}

std::string materialNames() {
    std::string out;
    for (const Material& m : materialPresets())
        out += (out.empty() ? "" : ", ") + m.name;
    return out;
}

} // namespace rubble
