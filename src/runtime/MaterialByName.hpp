#pragma once
// Private helper of the runtime: a material preset by name, as Structure::add and addObject take it.

#include <string>
#include <string_view>

#include "rubble/core/Result.hpp"
#include "rubble/structure/Material.hpp"

namespace rubble::detail {

/// The preset named `name` (the default for an empty name), or InvalidInput naming the presets.
inline Result<const Material*> materialByName(std::string_view name) {
    if (name.empty())
        return &defaultMaterial();
    if (const Material* m = findMaterial(name))
        return m;
    return Error{ErrorCode::InvalidInput,
                 "unknown material '" + std::string(name) + "'; expected one of " + materialNames()};
}

} // namespace rubble::detail
