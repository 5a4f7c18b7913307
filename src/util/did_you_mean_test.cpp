// The nearest-name suggestion of "unknown key" errors: distances and guesses worked out by hand.
#include "util/did_you_mean.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace quadcosim::util {
namespace {

TEST(DidYouMeanTest, SuggestsTheNearestKnownNameOnlyWhenItIsClose) {
  EXPECT_EQ(edit_distance("simulaton", "simulation"), 1u);
  EXPECT_EQ(edit_distance("q_angel", "q_angle"), 1u);  // two letters swapped: one slip
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("", "abc"), 3u);
  const std::vector<std::string> known = {"duration_s", "plant_rate_hz", "controller_rate_hz", "substeps"};
  EXPECT_EQ(nearest_name("duraton_s", known), "duration_s");
  EXPECT_EQ(nearest_name("duration", known), "duration_s");  // the unit left off
  EXPECT_EQ(nearest_name("plant_rate", known), "plant_rate_hz");
  EXPECT_EQ(nearest_name("colour", known), "");  // nothing close: no guess
  EXPECT_EQ(nearest_name("x", {"y"}), "");       // one letter for one letter is no resemblance
  EXPECT_EQ(did_you_mean("substep", known), "; did you mean 'substeps'?");
  EXPECT_EQ(did_you_mean("colour", known), "");
}

}  // namespace
}  // namespace quadcosim::util
