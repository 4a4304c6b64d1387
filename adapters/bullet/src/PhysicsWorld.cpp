#include "rubble/bullet/PhysicsWorld.hpp"

#include "rubble/bullet/Convert.hpp"

namespace rubble::bullet {

PhysicsWorld::PhysicsWorld() : PhysicsWorld(Config{}) {}

PhysicsWorld::PhysicsWorld(Config config) : config_(config) {
    collisionConfig_ = std::make_unique<btDefaultCollisionConfiguration>();
    dispatcher_ = std::make_unique<btCollisionDispatcher>(collisionConfig_.get());
    broadphase_ = std::make_unique<btDbvtBroadphase>();
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(),
                                                       collisionConfig_.get());
    world_->setGravity(toBt(config_.gravity));
    world_->setForceUpdateAllAabbs(false); // static bodies (thousands of frozen pieces) keep their bounds
    world_->getSolverInfo().m_numIterations = config_.solverIterations;
    world_->setInternalTickCallback(&PhysicsWorld::preTickThunk, this, true);
    world_->setInternalTickCallback(&PhysicsWorld::postTickThunk, this, false);
}

PhysicsWorld::~PhysicsWorld() {
    for (int i = world_->getNumConstraints() - 1; i >= 0; --i)
        world_->removeConstraint(world_->getConstraint(i));
    for (int i = world_->getNumCollisionObjects() - 1; i >= 0; --i)
        world_->removeCollisionObject(world_->getCollisionObjectArray()[i]);
}

int PhysicsWorld::step(double dt) {
    const int wanted = world_->stepSimulation(static_cast<btScalar>(dt), config_.maxSubSteps,
                                              static_cast<btScalar>(config_.fixedStep));
    return wanted < config_.maxSubSteps ? wanted : config_.maxSubSteps;
}

void PhysicsWorld::preTickThunk(btDynamicsWorld* world, btScalar dt) {
    auto* self = static_cast<PhysicsWorld*>(world->getWorldUserInfo());
    if (self->preTick_)
        self->preTick_(dt);
}

void PhysicsWorld::postTickThunk(btDynamicsWorld* world, btScalar dt) {
    auto* self = static_cast<PhysicsWorld*>(world->getWorldUserInfo());
    ++self->ticks_;
    if (self->postTick_)
        self->postTick_(dt);
}

} // namespace rubble::bullet
