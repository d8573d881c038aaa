#include "sunvo/runtime/frame_pool.hpp"

#include <opencv2/core.hpp>
#include <string>

namespace sunvo::runtime {

Status FramePoolOptions::validate() const {
  if (width < 16 || width > 8192) {
    return invalidArgument("frames.width: " + std::to_string(width) + " is outside [16, 8192]");
  }
  if (height < 16 || height > 8192) {
    return invalidArgument("frames.height: " + std::to_string(height) + " is outside [16, 8192]");
  }
  if (pool_depth < 2 || pool_depth > 256) {
    return invalidArgument("frames.pool_depth: " + std::to_string(pool_depth) +
                           " is outside [2, 256]");
  }
  return Status::ok();
}

FramePool::FramePool(const FramePoolOptions& options)
    : options_(options),
      slots_(static_cast<std::size_t>(options.pool_depth)),
      free_(static_cast<std::size_t>(options.pool_depth)),
      returns_(static_cast<std::size_t>(options.pool_depth), QueuePolicy::kReject) {}

Expected<std::unique_ptr<FramePool>> FramePool::create(const FramePoolOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  std::unique_ptr<FramePool> pool(new FramePool(options));
  for (std::size_t i = 0; i < pool->slots_.size(); ++i) {
    StereoFrame& f = pool->slots_[i].frame;
    f.left.create(options.height, options.width, CV_8UC1);
    f.right.create(options.height, options.width, CV_8UC1);
    f.left.setTo(0);
    f.right.setTo(0);
    if (options.color) {
      f.left_color.create(options.height, options.width, CV_8UC3);
      f.right_color.create(options.height, options.width, CV_8UC3);
      f.left_color.setTo(0);
      f.right_color.setTo(0);
    }
    // Highest index on top: slot 0 is handed out first.
    pool->free_[pool->slots_.size() - 1 - i] = static_cast<std::uint32_t>(i);
  }
  pool->free_count_ = pool->slots_.size();
  return pool;
}

bool FramePool::acquire(std::uint32_t* index) {
  std::uint32_t returned = 0;
  while (returns_.pop(&returned)) free_[free_count_++] = returned;
  if (free_count_ == 0) return false;
  *index = free_[--free_count_];
  return true;
}

void FramePool::recycle(std::uint32_t index) {
  if (free_count_ < free_.size()) free_[free_count_++] = index;
}

void FramePool::release(std::uint32_t index) {
  // The ring holds every slot, so this cannot fail.
  (void)returns_.push(index);
}

}  // namespace sunvo::runtime
