#include "rubble/bullet/Body.hpp"

#include "rubble/bullet/Convert.hpp"

namespace rubble::bullet {

btTransform Body::objectTransform() const {
    return rigid->getWorldTransform() * toBt(objectToBody).inverse();
}

} // namespace rubble::bullet
