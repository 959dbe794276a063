#include "projection_collision_avoidance/core/FollowerController.hpp"

namespace projection_collision_avoidance {

template class FollowerController<DoubleIntegrator1D>;
template class FollowerController<DoubleIntegrator2D>;
template class FollowerController<DoubleIntegrator3D>;
template class FollowerController<GenericDimensions>;

}  // namespace projection_collision_avoidance
