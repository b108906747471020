// splitPart: one labelled part of a split as a volume of its own (cut --parts).
#include <gtest/gtest.h>

#include "cutting/split.h"
#include "util/error.h"

namespace {

TEST(SplitPart, KeepsTheLabelledVoxelsAndFillsTheRestWithTheMinimum) {
  vs::Geometry g;
  g.dims = {4, 2, 1};
  vs::Volume<int16_t> v(g);
  vs::VolumeU8 labels(g, 0);
  const int16_t values[8] = {5, -7, 30, 12, 9, 100, -2, 0};
  const uint8_t part[8] = {1, 2, 2, 0, 1, 2, 0, 1};
  for (int i = 0; i < 8; ++i) v.data()[i] = values[i], labels.data()[i] = part[i];
  for (uint8_t label : {uint8_t(1), uint8_t(2)}) {
    const vs::Volume<int16_t> out = vs::splitPart(v, labels, label);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(out.data()[i], part[i] == label ? values[i] : int16_t(-7)) << i;
  }
}

TEST(SplitPart, DifferentDimensionsAreRefused) {
  vs::Geometry g, h;
  g.dims = {4, 2, 1};
  h.dims = {4, 1, 2};
  EXPECT_THROW(vs::splitPart(vs::VolumeF32(g), vs::VolumeU8(h, 0), 1), vs::InvalidArgument);
}

}  // namespace
