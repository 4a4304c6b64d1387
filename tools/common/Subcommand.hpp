#pragma once
// Self-registering subcommands shared by the `rubble` CLI and `rubble-bench`: each *Command.cpp / *Bench.cpp
// file registers one subcommand at static-initialisation time, so adding one touches no other file.

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace rubble::tools {

/// A subcommand: `setup` adds options to its CLI11 subcommand and returns the function that runs it
/// (returning the process exit code).
struct Subcommand {
    std::string name;
    std::string description;
    std::function<std::function<int()>(CLI::App&)> setup;
};

/// All subcommands registered in this executable.
std::vector<Subcommand>& registry();

/// Registers a subcommand: `static Registrar r{{"check", "...", setup}};`.
struct Registrar {
    explicit Registrar(Subcommand c) { registry().push_back(std::move(c)); }
};

/// Option check: a finite number (CLI::Range lets "nan" through, since NaN compares false both ways).
CLI::Validator finiteNumber();

/// Option check: a whole number from 0 to 2^64 - 1 written in decimal digits (CLI11 alone turns "-1" and
/// "2^64" into 2^64 - 1).
CLI::Validator unsigned64();

/// Parses argv, runs the chosen subcommand and returns its exit code (2 for usage errors).
int runMain(const std::string& description, const std::string& version, int argc, char** argv);

} // namespace rubble::tools
