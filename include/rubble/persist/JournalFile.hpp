#pragma once
/// \file JournalFile.hpp
/// The journal's binary encoding: 48 bytes per event, and a journal file (a header naming the world settings
/// the events need, the events, a CRC-32). Layout in docs/journal.md.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "rubble/runtime/Journal.hpp"

namespace rubble {

/// Bytes of one encoded journal event.
inline constexpr std::size_t kJournalEventBytes = 48;

/// The event in its 48-byte little-endian encoding.
RUBBLE_API std::array<std::uint8_t, kJournalEventBytes> encodeJournalEvent(const JournalEvent& event);
/// The event encoded at bytes (48 of them); an unknown kind, pattern or a non-finite number is an error
/// naming the field (offset is where the event starts, for the message).
RUBBLE_API Result<JournalEvent> decodeJournalEvent(const std::uint8_t* bytes, std::size_t offset = 0);

/// The world settings a journal replays correctly with.
struct RUBBLE_API JournalHeader {
    std::uint64_t seed = 1;             ///< DestructionWorld::Config::seed
    std::int32_t delayFrames = 2;       ///< DestructionWorld::Config::delayFrames
    std::uint64_t crumbleTriangles = 0; ///< DestructionWorld::Config::crumbleTriangles
    std::int32_t crumbleCells = 0;      ///< DestructionWorld::Config::crumbleCells
    double minPieceVolume = 0;          ///< DestructionWorld::Config::minPieceVolume
    std::string scene; ///< what the world was built from (e.g. a world.cfg path), informative

    /// Same fields.
    bool operator==(const JournalHeader&) const = default;
};

/// The header describing config.
RUBBLE_API JournalHeader journalHeaderOf(const DestructionWorld::Config& config, std::string scene = {});
/// Ok when config replays a journal with this header (deterministic, same seed, delay, crumbling and minimum
/// piece volume); otherwise an error naming the first field that differs.
RUBBLE_API Status checkJournalHeader(const JournalHeader& header, const DestructionWorld::Config& config);

/// A whole journal.
struct RUBBLE_API JournalFile {
    JournalHeader header;             ///< world settings
    std::vector<JournalEvent> events; ///< in order
};

/// The file's bytes.
RUBBLE_API std::vector<std::uint8_t> encodeJournal(const JournalFile& journal);
/// Parses a journal; errors name source, offset and field.
RUBBLE_API Result<JournalFile> decodeJournal(const std::uint8_t* data, std::size_t size,
                                             const std::string& source);
/// Writes a journal atomically (temporary file, then rename).
RUBBLE_API Status writeJournal(const std::filesystem::path& path, const JournalFile& journal);
/// Reads a journal file.
RUBBLE_API Result<JournalFile> readJournal(const std::filesystem::path& path);

/// Writes bytes to path atomically: a temporary file in the same folder, flushed to disk, then renamed over
/// path. A process killed at any point leaves either the old file or the new one, never a mix.
RUBBLE_API Status writeFileAtomic(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes);
/// The whole content of a regular file of at most 2 GiB, or an IoError naming it. Devices, FIFOs and sockets
/// are refused without blocking ("<file>: cannot read: it is a FIFO, not a regular file").
RUBBLE_API Result<std::vector<std::uint8_t>> readFileBinary(const std::filesystem::path& path);

} // namespace rubble
