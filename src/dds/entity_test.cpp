// dds::Entity against Cyclone's own view of its handles: an entity is alive (dds_get_parent answers
// with its participant) while its owner is, and gone (an error code) once the owner is.
#include "dds/entity.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <utility>

#include "dds/dds_test_support.hpp"
#include "dds/participant.hpp"

namespace quadcosim::dds {
namespace {

bool alive(dds_entity_t handle) { return dds_get_parent(handle) > 0; }

TEST(Entity, DeletesItsEntityWhenItGoes) {
  const Participant participant(test::private_env(DiscoveryRange::kOff));
  dds_entity_t handle = 0;
  {
    const Entity guard(check(dds_create_guardcondition(participant.handle()), "dds_create_guardcondition"));
    handle = guard.get();
    ASSERT_GT(handle, 0);
    EXPECT_EQ(dds_get_parent(handle), participant.handle());
  }
  EXPECT_FALSE(alive(handle));
}

TEST(Entity, AMoveHandsTheEntityOverAndResetDeletesItNow) {
  const Participant participant(test::private_env(DiscoveryRange::kOff));
  Entity first(check(dds_create_guardcondition(participant.handle()), "dds_create_guardcondition"));
  const dds_entity_t handle = first.get();
  Entity second(std::move(first));
  EXPECT_EQ(first.get(), 0);  // NOLINT(bugprone-use-after-move): a moved-from owner owns nothing
  EXPECT_EQ(second.get(), handle);
  first.reset();  // owns nothing: deletes nothing
  EXPECT_TRUE(alive(handle));
  Entity third;
  third = std::move(second);
  EXPECT_TRUE(alive(handle));
  third.reset();
  EXPECT_EQ(third.get(), 0);
  EXPECT_FALSE(alive(handle));
}

TEST(Entity, AnErrorCodeOwnsNothing) {
  Entity failed(DDS_RETCODE_BAD_PARAMETER);
  failed.reset();  // must not pass the error code to dds_delete
  EXPECT_EQ(failed.get(), 0);
}

TEST(Entity, AParticipantsEntitiesGoWithIt) {
  dds_entity_t participant_handle = 0;
  {
    const Participant participant(test::private_env(DiscoveryRange::kOff));
    participant_handle = participant.handle();
    EXPECT_TRUE(alive(participant_handle));
  }
  EXPECT_FALSE(alive(participant_handle));
}

}  // namespace
}  // namespace quadcosim::dds
