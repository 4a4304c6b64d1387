#include "Subcommand.hpp"

int main(int argc, char** argv) {
    return rubble::tools::runMain(
        "rubble-bench: side-by-side measurements; tables on stdout, CSV in bench/results/",
        "rubble-bench 0.1.0", argc, argv);
}
