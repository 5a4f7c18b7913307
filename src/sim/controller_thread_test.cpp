// sim::ControllerThread: the same numbers as the controller called directly, one call at a time on its
// own thread, parameters readable while a step blocks, a set refused when the thread stays busy, and a
// step's exception handed back.
#include "sim/controller_thread.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <thread>

#include "controllers/registry.hpp"

namespace quadcosim::sim {
namespace {

using namespace std::chrono_literals;

/// The paper controller, with a step that can be made to wait for a release, or to throw; it records
/// the threads that called it and whether two calls ever overlapped.
class Instrumented final : public control::Controller {
 public:
  explicit Instrumented(std::unique_ptr<control::Controller> inner) : inner_(std::move(inner)) {}
  std::string_view type() const override { return inner_->type(); }
  std::unique_ptr<control::Controller> clone() const override { return nullptr; }
  std::span<const control::ParameterSpec> parameters() const override { return inner_->parameters(); }
  std::optional<control::ParameterValue> get_parameter(std::string_view name) const override {
    return inner_->get_parameter(name);
  }
  std::string set_parameters(std::span<const control::Setting> s) override {
    const Enter e(*this);
    return inner_->set_parameters(s);
  }
  std::span<const std::string> output_names() const override { return inner_->output_names(); }
  void reset() override { inner_->reset(); }
  void step(const control::Observation& o, const control::Reference& r, double dt,
            control::ControllerOutput& out) override {
    const Enter e(*this);
    if (block) release.get_future().wait();
    if (fail) throw std::runtime_error("Instrumented.step: asked to fail");
    inner_->step(o, r, dt, out);
  }

  std::atomic<bool> block{false}, fail{false}, overlapped{false};
  std::promise<void> release;
  std::thread::id last_thread;

 private:
  struct Enter {
    explicit Enter(Instrumented& c) : c(c) {
      if (c.inside_.exchange(true)) c.overlapped = true;
      c.last_thread = std::this_thread::get_id();
    }
    ~Enter() { c.inside_ = false; }
    Instrumented& c;
  };
  std::unique_ptr<control::Controller> inner_;
  std::atomic<bool> inside_{false};
};

struct Fixture {
  model::VehicleParams vehicle;
  control::ControllerConfig config = controllers::make_config("paper", vehicle);
  control::Observation obs;
  control::Reference ref;
  Fixture() {
    obs.age_s = 0.0;
    obs.p_W = {0.1, -0.2, 1.0};
    obs.v_W = {0.0, 0.1, -0.3};
    ref.p_W = {0.0, 0.0, 2.0};
  }
  std::unique_ptr<Instrumented> instrumented() { return std::make_unique<Instrumented>(config.controller->clone()); }
};

TEST(ControllerThread, StepsGiveTheSameNumbersOnTheirOwnThread) {
  Fixture f;
  auto direct = f.config.controller->clone();
  auto owned = f.instrumented();
  Instrumented* c = owned.get();
  ControllerThread thread(std::move(owned));
  control::ControllerOutput a, b;
  a.outputs.assign(direct->output_names().size(), 0.0);
  b.outputs = a.outputs;
  for (int k = 0; k < 50; ++k) {
    f.obs.p_W.z() += 0.01;
    direct->step(f.obs, f.ref, 0.02, a);
    thread.step(f.obs, f.ref, 0.02, b);
    ASSERT_EQ(a.omega_rad_s, b.omega_rad_s) << "step " << k;
    ASSERT_EQ(a.outputs, b.outputs) << "step " << k;
  }
  EXPECT_NE(c->last_thread, std::this_thread::get_id());
}

TEST(ControllerThread, ABlockedStepLeavesParametersReadableAndRefusesSets) {
  Fixture f;
  auto owned = f.instrumented();
  Instrumented* c = owned.get();
  c->block = true;
  ControllerThread thread(std::move(owned));
  // A numeric parameter above its minimum: halfway down to the minimum is a valid change.
  std::string name;
  double lower = 0.0;
  for (const control::ParameterSpec& spec : thread.parameters()) {
    const auto v = thread.get_parameter(spec.name);
    if (!spec.is_choice() && v && std::get<double>(*v) > spec.min && std::isfinite(spec.min)) {
      name = std::string(spec.name);
      lower = (std::get<double>(*v) + spec.min) / 2;
      break;
    }
  }
  ASSERT_FALSE(name.empty());
  const auto before = thread.get_parameter(name);

  auto step = std::make_shared<ControllerThread::Step>();
  step->observation = f.obs;
  step->reference = f.ref;
  step->dt_s = 0.02;
  step->output.outputs.assign(thread.output_names().size(), 0.0);
  std::atomic<int> continued{0};
  ASSERT_TRUE(thread.start(step, [&](ControllerThread::Step&) { ++continued; }));
  EXPECT_FALSE(thread.wait_free(20'000'000));  // blocked
  EXPECT_TRUE(thread.busy());
  EXPECT_FALSE(thread.start(step)) << "a second step while the first runs";
  EXPECT_EQ(thread.get_parameter(name), before) << "read from the values as of the last return";

  const auto t0 = std::chrono::steady_clock::now();
  const control::Setting s{name, lower};
  const std::string refused = thread.set_parameters(std::span(&s, 1));
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(refused.find("the controller is busy"), std::string::npos) << refused;
  EXPECT_NEAR(waited, ControllerThread::kCallTimeoutNs / 1e9, 0.3);
  EXPECT_EQ(thread.get_parameter(name), before) << "nothing changed";

  c->release.set_value();
  EXPECT_TRUE(thread.wait_free(1'000'000'000));
  EXPECT_EQ(continued, 1);
  EXPECT_EQ(thread.set_parameters(std::span(&s, 1)), "");
  EXPECT_EQ(std::get<double>(*thread.get_parameter(name)), std::get<double>(s.value)) << "the cache follows a set";
  EXPECT_FALSE(c->overlapped);
}

TEST(ControllerThread, AFailedStepIsHandedBack) {
  Fixture f;
  auto owned = f.instrumented();
  owned->fail = true;
  ControllerThread thread(std::move(owned));
  control::ControllerOutput out;
  out.outputs.assign(thread.output_names().size(), 0.0);
  EXPECT_THROW(
      {
        try {
          thread.step(f.obs, f.ref, 0.02, out);
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "Instrumented.step: asked to fail");
          throw;
        }
      },
      std::runtime_error);
}

TEST(ControllerThread, AStepThatNeverReturnsIsLeftBehindAfterOneSecond) {
  Fixture f;
  auto owned = f.instrumented();
  owned->block = true;  // never released
  const auto t0 = std::chrono::steady_clock::now();
  {
    ControllerThread thread(std::move(owned));
    auto step = std::make_shared<ControllerThread::Step>();
    step->output.outputs.assign(thread.output_names().size(), 0.0);
    ASSERT_TRUE(
        thread.start(step, [](ControllerThread::Step&) { ADD_FAILURE() << "continuation after the owner left"; }));
  }
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NEAR(waited, 1.0, 0.3);
}

}  // namespace
}  // namespace quadcosim::sim
