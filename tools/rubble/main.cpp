#include "Subcommand.hpp"
#include "rubble/core/Version.hpp"

int main(int argc, char** argv) {
    return rubble::tools::runMain(
        "rubble: real-time destructible meshes (check, repair, fracture, decompose)",
        "rubble " RUBBLE_VERSION_STRING, argc, argv);
}
