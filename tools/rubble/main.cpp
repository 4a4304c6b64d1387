#include "Subcommand.hpp"

int main(int argc, char** argv) {
    return rubble::tools::runMain(
        "rubble: real-time destructible meshes (check, repair, fracture, decompose)", "rubble 0.1.0", argc,
        argv);
}
