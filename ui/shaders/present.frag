#version 450
// Shows the viewport's composed picture (8-bit, display-referred, QImage::Format_RGB32, i.e.
// B,G,R,X bytes) stretched over the swapchain image.
layout(std430, set = 0, binding = 0) readonly buffer Picture { uint texels[]; };
layout(push_constant) uniform Push {
  ivec2 pictureSize;
  vec2 targetSize;
  int srgbTarget;  // the swapchain encodes on write: hand it linear values
};
layout(location = 0) out vec4 color;

void main() {
  ivec2 p = clamp(ivec2(gl_FragCoord.xy / targetSize * vec2(pictureSize)), ivec2(0), pictureSize - 1);
  vec3 c = unpackUnorm4x8(texels[p.y * pictureSize.x + p.x]).zyx;
  if (srgbTarget != 0)
    c = mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
  color = vec4(c, 1.0);
}
