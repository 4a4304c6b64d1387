#pragma once
// Private helper of the io module: texture images placed next to a written file.

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/io/SceneIO.hpp"

namespace rubble::io {

/// True, with a warning, when a material's image is named by an absolute path: such an image is not used, so
/// that writers never copy files from anywhere on the machine into an output (relative paths, resolved
/// against the model's folder, are the model's own layout).
bool refuseAbsoluteImage(const std::string& material, const std::filesystem::path& image,
                         std::vector<std::string>& warnings);

/// Copies the images of texture maps into "textures/" next to a written file and gives their relative URIs.
class TextureFiles {
public:
    /// Images go to folder/textures.
    explicit TextureFiles(std::filesystem::path folder) : folder_(std::move(folder)) {}
    /// The URI (relative to the folder, '/' separated) under which map's image is found: a copy in textures/
    /// (written once per image), or the image's own path relative to the folder when it cannot be read.
    /// IoError when a copy cannot be written.
    Result<std::string> place(const TextureMap& map);

private:
    std::filesystem::path folder_;
    std::map<std::string, std::string> placed_; // source key -> URI
    std::set<std::string> names_;               // file names used in textures/
};

} // namespace rubble::io
