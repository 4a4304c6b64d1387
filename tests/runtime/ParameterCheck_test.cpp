// The C++ face of the shared parameter table (tests/data/parameter_cases.tsv): fracture() refuses every
// out-of-range impulse, normal, point and cells with the table's message, addObject every density, and
// checkPieceBudget every cells x depth; the values marked ok are accepted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {
namespace {

struct Case {
    std::string faces, name, value, message;
};

std::vector<Case> cases() {
    std::ifstream in(test::sourceDir() / "tests/data/parameter_cases.tsv");
    std::vector<Case> out;
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#')
            continue;
        std::istringstream fields(line);
        Case c;
        std::getline(fields, c.faces, '\t');
        std::getline(fields, c.name, '\t');
        std::getline(fields, c.value, '\t');
        std::getline(fields, c.message);
        out.push_back(c);
    }
    return out;
}

std::vector<double> numbers(const std::string& text) {
    std::vector<double> v;
    std::istringstream in(text);
    std::string part;
    while (std::getline(in, part, ','))
        v.push_back(std::strtod(part.c_str(), nullptr));
    return v;
}

Vec3 vec(const std::string& text) {
    const std::vector<double> v = numbers(text);
    return {v.at(0), v.at(1), v.at(2)};
}

/// The outcome of one case through the C++ API: "ok" or the error message.
std::string run(const Case& c) {
    if (c.name == "cells x depth") {
        const std::vector<double> v = numbers(c.value);
        const Status s = checkPieceBudget(static_cast<int>(v.at(0)), static_cast<int>(v.at(1)));
        return s ? "ok" : s.message();
    }
    if (c.name == "density") {
        DestructionWorld world(DestructionWorld::Config{});
        ObjectDesc desc;
        desc.mesh = makeBox({0, 0, 0}, {1, 1, 1});
        desc.density = std::strtod(c.value.c_str(), nullptr);
        const Result<ObjectId> added = world.addObject(desc);
        return added ? "ok" : added.error().message;
    }
    Impact impact;
    impact.point = {0.5, 0.5, 1};
    impact.normal = {0, 0, 1};
    impact.impulse = 100;
    FractureParams params;
    if (c.name == "impulse")
        impact.impulse = std::strtod(c.value.c_str(), nullptr);
    else if (c.name == "normal")
        impact.normal = vec(c.value);
    else if (c.name == "point")
        impact.point = vec(c.value);
    else if (c.name == "cells") {
        params.pattern = CellPattern::Shatter;
        params.cells = static_cast<int>(std::strtol(c.value.c_str(), nullptr, 10));
    } else if (c.name == "roughness")
        params.roughness.amplitude = std::strtod(c.value.c_str(), nullptr);
    else if (c.name == "hurst") {
        params.roughness.amplitude = 0.1;
        params.roughness.hurst = std::strtod(c.value.c_str(), nullptr);
    } else if (c.name == "feature_size") {
        params.roughness.amplitude = 0.1;
        params.roughness.featureSize = std::strtod(c.value.c_str(), nullptr);
    } else {
        ADD_FAILURE() << "no C++ case for " << c.name;
    }
    const Result<FractureResult> r = fracture(makeBox({0, 0, 0}, {1, 1, 1}), impact, params, 1);
    if (r)
        return "ok";
    EXPECT_EQ(r.error().code, ErrorCode::InvalidInput) << r.error().message;
    return r.error().message;
}

TEST(ParameterCheck, EveryTableCaseRefusedOrAcceptedByTheCppApi) {
    const std::vector<Case> all = cases();
    ASSERT_GE(all.size(), 20u);
    int run_ = 0;
    for (const Case& c : all) {
        if (c.faces.find("cpp") == std::string::npos)
            continue;
        ++run_;
        const std::string got = run(c);
        if (c.message == "ok")
            EXPECT_EQ(got, "ok") << c.name << " " << c.value;
        else
            EXPECT_NE(got.find(c.message), std::string::npos)
                << c.name << " " << c.value << ": got '" << got << "', expected '" << c.message << "'";
    }
    EXPECT_GE(run_, 20);
}

TEST(ParameterCheck, RangesAreNamedOnceAndDescribed) {
    for (const ParamRange& r : kParamRanges) {
        EXPECT_EQ(findParamRange(r.name), &r);
        EXPECT_FALSE(describeParamRange(r).empty());
    }
    EXPECT_EQ(findParamRange("no such parameter"), nullptr);
    EXPECT_FALSE(checkParam("no such parameter", 1.0L));
    EXPECT_FALSE(checkParam("cells", 2.5L)); // whole numbers only
    EXPECT_TRUE(checkParam("seed", 18446744073709551615.0L));
    EXPECT_FALSE(checkParamText("seed", "1e3"));
    EXPECT_FALSE(checkParamText("impulse", "12abc"));
    EXPECT_EQ(checkParamText("impulse", "-1").message(), checkParam("impulse", -1.0L).message());
}

TEST(ParameterCheck, ASubmittedImpactOutOfRangeIsIgnored) {
    DestructionWorld world(DestructionWorld::Config{});
    ObjectDesc desc;
    desc.mesh = makeBox({0, 0, 0}, {1, 1, 1});
    const Result<ObjectId> id = world.addObject(desc);
    ASSERT_TRUE(id);
    Impact bad;
    bad.point = {0.5, 0.5, 1};
    bad.normal = {0, 0, 0};
    EXPECT_FALSE(world.submitImpact(*id, bad));
    bad.normal = {0, 0, 1};
    bad.impulse = -1;
    EXPECT_FALSE(world.submitImpact(*id, bad));
    bad.impulse = 10;
    EXPECT_TRUE(world.submitImpact(*id, bad));
}

TEST(ParameterCheck, AWorldConfigOutOfRangeRefusesEveryObjectAndSaysWhich) {
    ObjectDesc desc;
    desc.mesh = makeBox({0, 0, 0}, {1, 1, 1});
    auto refusal = [&](DestructionWorld::Config c) {
        EXPECT_FALSE(DestructionWorld::checkConfig(c));
        DestructionWorld world(c);
        const Result<ObjectId> id = world.addObject(desc);
        EXPECT_FALSE(id);
        EXPECT_TRUE(world.objects().empty());
        return id ? std::string() : id.error().message;
    };
    DestructionWorld::Config c;
    EXPECT_TRUE(DestructionWorld::checkConfig(c));
    c.decomposition.maxParts = 5000;
    EXPECT_EQ(refusal(c), "addObject: world config: decomposition: maxParts 5000 is outside [1, 1024]");
    c = {};
    c.decomposition.concavity = std::nan("");
    EXPECT_NE(refusal(c).find("concavity nan"), std::string::npos);
    c = {};
    c.minPieceVolume = -1;
    EXPECT_NE(refusal(c).find("minPieceVolume -1"), std::string::npos);
    c = {};
    c.crumbleCells = -2;
    EXPECT_NE(refusal(c).find("crumbleCells -2"), std::string::npos);
    DecompositionParams none;
    none.maxParts = 0;
    const auto parts = decompose(desc.mesh, none);
    ASSERT_FALSE(parts);
    EXPECT_EQ(parts.error().message, "decompose: maxParts 0 is outside [1, 1024]");
}

} // namespace
} // namespace rubble
