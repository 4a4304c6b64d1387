#include "rubble/core/ParameterCheck.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

Status checkFractureParams(const Impact& impact, const FractureParams& params) {
    for (Status s : {checkParam("point", impact.point), checkParam("normal", impact.normal),
                     checkParam("impulse", impact.impulse), checkParam("cells", params.cells)})
        if (!s)
            return s;
    return {};
}

} // namespace rubble
