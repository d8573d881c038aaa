#include "sunvo/runtime/frame_pool.hpp"

#include <gtest/gtest.h>

#include <set>

namespace sunvo::runtime {
namespace {

TEST(FramePool, SlotsAreAllocatedOnceAndHandedOutUntilExhausted) {
  FramePoolOptions o;
  o.width = 64;
  o.height = 32;
  o.pool_depth = 3;
  auto pool = FramePool::create(o);
  ASSERT_TRUE(pool) << pool.status().toString();
  FramePool& p = **pool;
  EXPECT_EQ(p.depth(), 3u);
  std::set<std::uint32_t> got;
  std::uint32_t i = 0;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(p.acquire(&i));
    got.insert(i);
    EXPECT_EQ(p.slot(i).frame.left.cols, 64);
    EXPECT_EQ(p.slot(i).frame.right.rows, 32);
    EXPECT_TRUE(p.slot(i).frame.left_color.empty());
  }
  EXPECT_EQ(got.size(), 3u);
  EXPECT_FALSE(p.acquire(&i));
  const uchar* data = p.slot(1).frame.left.data;
  p.release(1);  // from the consumer thread's side
  ASSERT_TRUE(p.acquire(&i));
  EXPECT_EQ(i, 1u);
  EXPECT_EQ(p.slot(1).frame.left.data, data);  // the same buffer, not a new one
  p.recycle(1);                                // the producer's own drop
  EXPECT_EQ(p.freeCount(), 1u);
}

TEST(FramePool, OptionsNameTheBadKey) {
  FramePoolOptions o;
  o.pool_depth = 1;
  EXPECT_NE(o.validate().message().find("frames.pool_depth"), std::string::npos);
  o = FramePoolOptions{};
  o.width = 8;
  EXPECT_NE(o.validate().message().find("frames.width: 8 is outside"), std::string::npos);
  o = FramePoolOptions{};
  o.color = true;
  o.width = 32;
  o.height = 16;
  auto pool = FramePool::create(o);
  ASSERT_TRUE(pool);
  EXPECT_EQ((*pool)->slot(0).frame.left_color.type(), CV_8UC3);
}

}  // namespace
}  // namespace sunvo::runtime
