// posefilter/mask_prior.h — instance masks as a stage-1 prior: what a Mask R-CNN- or
// SAM-style front end gives, or a dataset's label image (YCB-Video's label.png).
//
// A mask image holds one id per pixel (0 = background); a class map says which class each id
// is. An *instance label* image has one id per object instance; a *class label* image (as
// YCB-Video's label.png) has one id per class, and then each class is one instance. Either
// way every id becomes one InstanceMask: its pixels, its class and its box. The filter looks
// for the object of each instance with SceneInput::mask set to its pixels and a prior made
// of one detection, the mask's box (MaskDetection).
//
// Class map files (JSON): {"1": "002_master_chef_can", "7": "mug", ...} (id → class), or a
// list ["002_master_chef_can", ...] (id i + 1 → the i-th class). Without a class map the ids
// are YCB-Video's: 1..21 in YcbVideoClassNames() order.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "posefilter/depth_image.h"
#include "posefilter/prior.h"

namespace posefilter {

struct InstanceMask {
  int id = 0;                         // the id in the mask image
  std::string cls;                    // its class
  std::vector<std::uint8_t> pixels;   // width × height, 1 on the instance
  Box box;                            // box of its pixels (ProjectedBox's convention)
  int area = 0;                       // pixels
};

// Reads a class map (see above). Throws Error naming the file on a missing or malformed
// file, an id that is not a positive integer below 65536, or an empty class name.
std::map<int, std::string> ReadMaskClasses(const std::string& path);
// id i + 1 → YcbVideoClassNames()[i].
std::map<int, std::string> YcbVideoMaskClasses();

// The instances of a mask image, in id order. `what` (the file) names the image in errors:
// an id that the class map does not know, or an image without any instance ("the mask is
// empty"). Throws Error.
std::vector<InstanceMask> MasksFromLabels(const LabelImage& labels, const std::map<int, std::string>& classes,
                                          const std::string& what);

// The detection of a mask: its class, `score`, its pixels' box.
Detection MaskDetection(const InstanceMask& mask, double score = 1.0);

}  // namespace posefilter
