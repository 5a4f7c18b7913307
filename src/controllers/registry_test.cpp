// The registry's promises: the default type is its first entry and is the paper's controller, and no
// compiled controller asks for a thread of its own (only the Python ones do: tests/python).
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

TEST(ControllerRegistry, NoCompiledControllerWantsAThreadOfItsOwn) {
  for (const ControllerType& t : controller_types()) {
    const control::ControllerConfig config = make_config(t.name, model::VehicleParams{});
    EXPECT_FALSE(config.wants_own_thread()) << t.name;
    EXPECT_FALSE(t.make(model::VehicleParams{})->wants_own_thread()) << t.name;
  }
}

}  // namespace
}  // namespace quadcosim::controllers
