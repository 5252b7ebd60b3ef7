#include "method.hpp"

namespace nidevo::bench {

#if NIDEVO_HAVE_OPENCV_RGBD
void addOpenCvPeers(std::vector<std::unique_ptr<Method>>* methods);
#endif
#if NIDEVO_HAVE_OPEN3D
void addOpen3dPeers(std::vector<std::unique_ptr<Method>>* methods);
#endif

std::vector<std::unique_ptr<Method>> makePeers() {
  std::vector<std::unique_ptr<Method>> methods;
#if NIDEVO_HAVE_OPENCV_RGBD
  addOpenCvPeers(&methods);
#endif
#if NIDEVO_HAVE_OPEN3D
  addOpen3dPeers(&methods);
#endif
  return methods;
}

}  // namespace nidevo::bench
