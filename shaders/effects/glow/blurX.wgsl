// blurX: horizontal Gaussian blur with the standard deviation in output pixels
// (the code, shared with blurY, is lib/blur_axis.wgsl).
#define VERTICAL 0
#include "lib/blur_axis.wgsl"
