#pragma once
/// \file Export.hpp
/// RUBBLE_API marks what librubble.so exports; the library is built with hidden visibility
/// (docs/architecture.md).

#if defined(__GNUC__) || defined(__clang__)
#define RUBBLE_API [[gnu::visibility("default")]]
#else
#define RUBBLE_API
#endif
