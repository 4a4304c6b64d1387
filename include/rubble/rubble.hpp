#pragma once
/// \file rubble.hpp
/// What a game includes: the engine-neutral runtime and its binding interface, scenes, mesh files, saves and
/// replays, and the result and log types. Tools reach the kernel's layers by their own headers
/// (rubble/<layer>/...); the C API is rubble/rubble.h.

#include "rubble/core/Log.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/core/Version.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/fracture/FractureRequest.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "rubble/runtime/JournalPlayer.hpp"
#include "rubble/runtime/PhysicsBinding.hpp"
#include "rubble/runtime/SceneLoader.hpp"
