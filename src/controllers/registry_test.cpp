// The registry's promises: the default type is its first entry and is the paper's controller.
#include "controllers/registry.hpp"

#include <gtest/gtest.h>

#include <string>

namespace quadcosim::controllers {
namespace {

TEST(ControllerRegistry, TheDefaultTypeIsThePapersControllerAndComesFirst) {
  EXPECT_EQ(std::string(kDefaultControllerType), "paper");
  ASSERT_FALSE(controller_types().empty());
  EXPECT_EQ(controller_types().front().name, kDefaultControllerType);
  EXPECT_EQ(controller_type_list().front(), "paper");
  EXPECT_EQ(make_config(kDefaultControllerType, model::VehicleParams{}).type(), "paper");
}

}  // namespace
}  // namespace quadcosim::controllers
