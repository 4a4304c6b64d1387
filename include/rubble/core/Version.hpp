#pragma once
/// \file Version.hpp
/// Rubble's version; the top-level CMakeLists.txt reads its project version from these three lines.

#define RUBBLE_VERSION_MAJOR 0 ///< incompatible API changes
#define RUBBLE_VERSION_MINOR 1 ///< compatible additions
#define RUBBLE_VERSION_PATCH 0 ///< fixes

#define RUBBLE_VERSION_TEXT_(a, b, c) #a "." #b "." #c
#define RUBBLE_VERSION_TEXT(a, b, c) RUBBLE_VERSION_TEXT_(a, b, c)
/// "MAJOR.MINOR.PATCH"
#define RUBBLE_VERSION_STRING                                                                                \
    RUBBLE_VERSION_TEXT(RUBBLE_VERSION_MAJOR, RUBBLE_VERSION_MINOR, RUBBLE_VERSION_PATCH)
/// One number that compares versions: MAJOR * 10000 + MINOR * 100 + PATCH.
#define RUBBLE_VERSION (RUBBLE_VERSION_MAJOR * 10000 + RUBBLE_VERSION_MINOR * 100 + RUBBLE_VERSION_PATCH)
