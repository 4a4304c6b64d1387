#pragma once
// The host of the netplay tests: the journal scene on the toy engine, served on 127.0.0.1 (a free port),
// joining clients' snapshots taking their placements from its runtime.

#include <gtest/gtest.h>

#include <memory>

#include "JournalScene.hpp"
#include "rubble/enet/NetHost.hpp"

namespace rubble::test {

/// A JournalRig (one worker) with a NetHost listening on it; `server` is null when listening failed.
struct NetHostRig {
    NetHostRig() : rig(1), config(journalConfig(1).world) {
        auto listened = net::NetHost::listen(rig.runtime, config, "127.0.0.1", 0);
        EXPECT_TRUE(listened) << (listened ? std::string() : listened.error().message);
        if (!listened)
            return;
        server = std::move(*listened);
        server->setPlacementSource([this] { return rig.runtime.placements(); });
    }
    NetHostRig(const NetHostRig&) = delete;
    NetHostRig& operator=(const NetHostRig&) = delete;
    JournalRig rig;
    DestructionWorld::Config config; ///< the world's settings (clients use them too)
    std::unique_ptr<net::NetHost> server;
};

} // namespace rubble::test
