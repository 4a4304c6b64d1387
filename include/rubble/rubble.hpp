#pragma once
/// \file rubble.hpp
/// The game-facing API in one include: meshes and their files, checks and repair, the fracture kernel, convex
/// decomposition, the engine-neutral runtime (DestructionWorld, DestructionRuntime, PhysicsBinding), and the
/// destruction journal and snapshots (JournalPlayer, JournalFile, Snapshot).
/// Tools-only headers (TimingReport.hpp, SceneConfig.hpp, SceneLoader.hpp, MeshSimplify.hpp, Islands.hpp,
/// ThreadPool.hpp) are included on their own. The C API is rubble/rubble.h.

#include "rubble/CollisionTolerance.hpp"
#include "rubble/ConvexDecomposition.hpp"
#include "rubble/DecompositionFile.hpp"
#include "rubble/DestructionRuntime.hpp"
#include "rubble/DestructionWorld.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/Frame.hpp"
#include "rubble/Journal.hpp"
#include "rubble/JournalFile.hpp"
#include "rubble/JournalPlayer.hpp"
#include "rubble/Log.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/Mesh.hpp"
#include "rubble/MeshCheck.hpp"
#include "rubble/MeshIO.hpp"
#include "rubble/MeshRepair.hpp"
#include "rubble/ParameterCheck.hpp"
#include "rubble/PartConcavity.hpp"
#include "rubble/PhysicsBinding.hpp"
#include "rubble/Random.hpp"
#include "rubble/Result.hpp"
#include "rubble/SceneIO.hpp"
#include "rubble/Snapshot.hpp"
#include "rubble/Vec3.hpp"
#include "rubble/Version.hpp"
