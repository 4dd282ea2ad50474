// blurY: vertical Gaussian blur with the standard deviation in output pixels
// (the code, shared with blurX, is lib/blur_axis.wgsl).
#define VERTICAL 1
#include "lib/blur_axis.wgsl"
