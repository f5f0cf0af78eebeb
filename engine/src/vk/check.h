// Every VkResult goes through checkVk, which names the result and what was being done.
#pragma once

#include <vulkan/vulkan.h>

#include <string>

#include "retile/error.h"

namespace retile::vk {

const char* resultName(VkResult r);

// Thrown for device loss, so callers can tell it from other failures and rebuild the device.
class DeviceLost : public Error {
 public:
  using Error::Error;
};

void throwVk(VkResult r, const char* what);

inline void checkVk(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throwVk(r, what);
}

}  // namespace retile::vk
