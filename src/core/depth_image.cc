// core/depth_image.cc — the depth image's own operations (its PNG files: src/io/image_io.cc).
#include "posefilter/depth_image.h"

#include <algorithm>

namespace posefilter {

size_t DepthImage::CountValid() const {
  return static_cast<size_t>(std::count_if(data.begin(), data.end(), [](float d) { return d > 0.f; }));
}

}  // namespace posefilter
