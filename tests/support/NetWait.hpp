#pragma once
// Waiting in the netplay tests: for a condition, with a deadline generous enough for a loaded machine under
// the sanitizers, never for an assumed number of frames or milliseconds.

#include <chrono>

namespace rubble::test {

/// Calls pump() (it services the network; false = give up) until done() holds or 2 minutes passed; true when
/// done() holds.
template <class Done, class Pump>
bool waitFor(const Done& done, const Pump& pump) {
    for (const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(2); !done();)
        if (std::chrono::steady_clock::now() > end || !pump())
            return false;
    return true;
}

} // namespace rubble::test
