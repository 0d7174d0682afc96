// A recorded session's replay (issue 10): the input log stored in chunks reads back exactly, a
// damaged chunk is refused naming what is wrong, and SessionReplay, built again from the scene,
// goes through the run's states to the last bit however it is sought: straight to the end, in
// steps of a few cycles, forward from the middle, or back to the middle (from rest again).
#include "liversim/engine/model_building.h"
#include "liversim/haptics/emulated_devices.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/sessions/session_replay.h"
#include "liversim/sessions/session_store.h"

#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <thread>

namespace liversim {
namespace {

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

bool same_positions(const NodeArray& a, const NodeArray& b) {
  return a.size() == b.size() && a.x == b.x && a.y == b.y && a.z == b.z;
}

std::vector<SimulationInput> every_kind_of_input() {
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.pose.origin_m = {0.01, -0.02, 1.0 / 3.0};
  forceps.pose.orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  forceps.jaw_opening = 0.25;
  forceps.blade_armed = false;
  forceps.geometry.jaw_length_m = 0.0175;
  const auto input = [](SimulationInput::Kind kind) {
    SimulationInput made;
    made.kind = kind;
    return made;
  };
  SimulationInput tool = input(SimulationInput::Kind::tool);
  tool.tool = forceps;
  const SimulationInput no_tool = input(SimulationInput::Kind::tool);
  SimulationInput springs = input(SimulationInput::Kind::springs);
  springs.springs = {{7, {0.1, 0.2, 0.3}, 300.0, 2.5}, {123456, {-1e-9, 0.0, 5e300}, 1.0}};
  const SimulationInput no_springs = input(SimulationInput::Kind::springs);
  SimulationInput cycle = input(SimulationInput::Kind::cycle);
  cycle.steps = 17;
  cycle.check_energy = true;
  cycle.servo_time_s = 12.345678901234567;
  SimulationInput untimed_cycle = input(SimulationInput::Kind::cycle);
  untimed_cycle.steps = 1;
  const SimulationInput take_out = input(SimulationInput::Kind::take_out_specimens);
  SimulationInput left_tool = tool;
  left_tool.hand = Hand::left;
  SimulationInput left_no_tool = no_tool;
  left_no_tool.hand = Hand::left;
  return {tool,       springs,       cycle,     take_out,    no_tool,
          no_springs, untimed_cycle, left_tool, left_no_tool};
}

TEST(SessionLog, InputChunksReadBackExactly) {
  const std::vector<SimulationInput> inputs = every_kind_of_input();
  const std::vector<SimulationInput> read = decode_input_chunk(encode_input_chunk(inputs));
  ASSERT_EQ(read.size(), inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    SCOPED_TRACE(i);
    const SimulationInput& a = inputs[i];
    const SimulationInput& b = read[i];
    EXPECT_EQ(a.kind, b.kind);
    if (a.kind == SimulationInput::Kind::tool) {
      EXPECT_EQ(a.hand, b.hand);
    }
    ASSERT_EQ(a.tool.has_value(), b.tool.has_value());
    if (a.tool) {
      EXPECT_EQ(a.tool->kind, b.tool->kind);
      EXPECT_EQ(a.tool->pose.origin_m, b.tool->pose.origin_m);
      EXPECT_EQ(a.tool->pose.orientation.coeffs(), b.tool->pose.orientation.coeffs());
      EXPECT_EQ(a.tool->jaw_opening, b.tool->jaw_opening);
      EXPECT_EQ(a.tool->blade_armed, b.tool->blade_armed);
      EXPECT_EQ(a.tool->geometry.jaw_length_m, b.tool->geometry.jaw_length_m);
      EXPECT_EQ(a.tool->geometry.blade_half_thickness_m, b.tool->geometry.blade_half_thickness_m);
    }
    ASSERT_EQ(a.springs.size(), b.springs.size());
    for (std::size_t s = 0; s < a.springs.size(); ++s) {
      EXPECT_EQ(a.springs[s].node, b.springs[s].node);
      EXPECT_EQ(a.springs[s].anchor_m, b.springs[s].anchor_m);
      EXPECT_EQ(a.springs[s].stiffness_n_per_m, b.springs[s].stiffness_n_per_m);
      EXPECT_EQ(a.springs[s].damping_n_s_per_m, b.springs[s].damping_n_s_per_m);
    }
    EXPECT_EQ(a.steps, b.steps);
    EXPECT_EQ(a.check_energy, b.check_energy);
    EXPECT_TRUE(same_bits(a.servo_time_s, b.servo_time_s)) << b.servo_time_s;
  }
  EXPECT_TRUE(decode_input_chunk(encode_input_chunk({})).empty());
}

std::string decode_error(std::vector<std::uint8_t> bytes) {
  try {
    decode_input_chunk(bytes);
  } catch (const StorageError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SessionLog, ADamagedInputChunkIsRefusedNamingWhatIsWrong) {
  const std::vector<std::uint8_t> good = encode_input_chunk(every_kind_of_input());
  std::vector<std::uint8_t> bytes = good;
  bytes[0] = 'X';
  EXPECT_NE(decode_error(bytes).find("\"LSI1\""), std::string::npos) << decode_error(bytes);
  bytes = good;
  bytes.resize(bytes.size() - 3);
  EXPECT_NE(decode_error(bytes).find("ends inside input 7"), std::string::npos)
      << decode_error(bytes);
  bytes = good;
  bytes.push_back(0);
  EXPECT_NE(decode_error(bytes).find("1 bytes after its last input"), std::string::npos)
      << decode_error(bytes);
  bytes = good;
  bytes[8] = 9;  // the first input's kind
  EXPECT_NE(decode_error(bytes).find("input 0 of an input chunk has kind 9"), std::string::npos)
      << decode_error(bytes);
  bytes = good;
  bytes[10] = 7;  // the first input's tool kind (after its kind and presence)
  EXPECT_NE(decode_error(bytes).find("has tool 7"), std::string::npos) << decode_error(bytes);
  bytes = good;
  bytes[4] = 0xff;  // the count
  bytes[7] = 0x7f;
  EXPECT_NE(decode_error(bytes).find("claims"), std::string::npos) << decode_error(bytes);
  // A cycle of 0 steps: the record of one cycle alone, its steps 0.
  const SimulationInput cycle{SimulationInput::Kind::cycle, std::nullopt, {}, 1, false, 0.5};
  bytes = encode_input_chunk(std::span(&cycle, 1));
  bytes[9] = 0;
  EXPECT_NE(decode_error(bytes).find("a cycle of 0 steps"), std::string::npos)
      << decode_error(bytes);
  // A take-out of specimens this version does not know (which: 0, every free body).
  SimulationInput take_out;
  take_out.kind = SimulationInput::Kind::take_out_specimens;
  bytes = encode_input_chunk(std::span(&take_out, 1));
  ASSERT_EQ(bytes.size(), 10u);
  bytes[9] = 5;
  EXPECT_NE(decode_error(bytes).find("takes out specimens 5"), std::string::npos)
      << decode_error(bytes);
}

// A live run of the workstation's scene simulation, its input logged with the servo's clock: a
// probe pressed into the liver, then a scalpel pressed until it breaks in and drawn 7 cm across.
class SessionReplayTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new SceneSetup(default_scene(1500));
    const auto model =
        std::make_shared<const SimModel>(build_model(scene_->mesh, scene_->model_options));
    TrajectoryDevice still("still", {{0.0, Eigen::Vector3d::Zero(), 0}});
    ServoLoop servo(still, ServoLoop::Options{});  // not started: its clock stamps the cycles
    live_ = make_scene_simulation(model, scene_->visual.surface).release();
    live_->set_haptic_servo(&servo);
    live_->log_inputs(true);
    live_->start();
    Eigen::AlignedBox3d box;
    for (std::size_t n = 0; n < model->node_count; ++n) box.extend(model->rest_position_m.at(n));
    const auto wait_simulated = [&](double seconds) {
      live_->update_snapshot();
      const double until = live_->snapshot().time_s + seconds;
      for (int k = 0; k < 20'000 && live_->snapshot().time_s < until; ++k) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        live_->update_snapshot();
      }
    };
    Tool probe;
    probe.pose.origin_m = {box.center().x() + 0.02, box.center().y(), box.max().z()};
    for (int k = 0; k < 8; ++k) {
      probe.pose.origin_m.z() -= 0.001;
      live_->set_tool(probe);
      wait_simulated(0.01);
    }
    // The top of the liver where the scalpel goes in: the highest rest node near there.
    const Eigen::Vector3d entry(box.center().x() - 0.02, box.center().y(), 0.0);
    double top_z = box.min().z();
    for (std::size_t n = 0; n < model->node_count; ++n) {
      const Eigen::Vector3d p = model->rest_position_m.at(n);
      if (std::abs(p.x() - entry.x()) < 0.01 && std::abs(p.y() - entry.y()) < 0.01)
        top_z = std::max(top_z, p.z());
    }
    Tool scalpel;
    scalpel.kind = ToolKind::scalpel;
    scalpel.pose.origin_m = {entry.x(), entry.y(), top_z + scalpel.geometry.blade_length_m};
    for (int k = 0; k < 40 && !live_->snapshot().hand(Hand::right).blade_cutting; ++k) {
      scalpel.pose.origin_m.z() -= 0.001;
      live_->set_tool(scalpel);
      wait_simulated(0.01);
    }
    broke_in_ = live_->snapshot().hand(Hand::right).blade_cutting;
    for (int k = 0; k < 20; ++k) {  // in: the blade sinks without pushing
      scalpel.pose.origin_m.z() -= 0.001;
      live_->set_tool(scalpel);
      wait_simulated(0.01);
    }
    in_after_sinking_ = live_->snapshot().hand(Hand::right).blade_cutting;
    // Drawn until it has cut, then 1 cm on. On this coarse mesh (elements about 2 cm across) a cut
    // parts only elements the blade has passed all the way through: the first faces part after 4
    // to 6 cm, depending on how deep the blade broke in, which the threads' timing decides.
    for (int k = 0, after_cut = 0; k < kMostDrawnMm && after_cut < 10; ++k) {
      scalpel.pose.origin_m.x() += 0.001;
      live_->set_tool(scalpel);
      wait_simulated(0.01);
      ++positions_drawn_;
      if (live_->snapshot().hand(Hand::right).blade_cutting) ++cycles_drawn_in_;
      if (live_->snapshot().topology_version > 0) ++after_cut;
    }
    live_->set_tool(std::nullopt);
    wait_simulated(0.05);
    live_->stop();
    live_->set_haptic_servo(nullptr);
    log_ = new std::vector<SimulationInput>(live_->take_input_log());
  }
  static void TearDownTestSuite() {
    delete live_;
    delete log_;
    delete scene_;
  }

  static void expect_the_run(RealtimeSimulation& replayed) {
    EXPECT_EQ(replayed.state().step_count, live_->state().step_count);
    EXPECT_EQ(replayed.state().time_s, live_->state().time_s);
    ASSERT_EQ(replayed.model().node_count, live_->model().node_count);
    EXPECT_TRUE(same_positions(replayed.state().position_m, live_->state().position_m))
        << "the replay's positions differ from the run's";
    EXPECT_TRUE(same_positions(replayed.state().velocity_m_per_s, live_->state().velocity_m_per_s));
    // The snapshot a viewport draws is the replayed state's.
    replayed.update_snapshot();
    EXPECT_TRUE(same_positions(replayed.snapshot().position_m, live_->state().position_m));
  }

  static SceneSetup* scene_;
  static inline bool broke_in_ = false;
  static inline bool in_after_sinking_ = false;
  static constexpr int kMostDrawnMm = 110;
  static inline int positions_drawn_ = 0;
  static inline int cycles_drawn_in_ = 0;
  static RealtimeSimulation* live_;
  static std::vector<SimulationInput>* log_;
};

SceneSetup* SessionReplayTest::scene_ = nullptr;
RealtimeSimulation* SessionReplayTest::live_ = nullptr;
std::vector<SimulationInput>* SessionReplayTest::log_ = nullptr;

TEST_F(SessionReplayTest, TheRunCutTheLiverAndEveryCycleIsOnTheServoClock) {
  ASSERT_TRUE(broke_in_) << "the scalpel did not break in";
  live_->update_snapshot();
  EXPECT_GT(live_->snapshot().topology_version, 0u)
      << "the scalpel cut nothing; in after sinking: " << in_after_sinking_ << ", in at "
      << cycles_drawn_in_ << " of " << positions_drawn_
      << " positions drawn, halted: " << live_->stats().halted
      << ", rollbacks: " << live_->stats().rollbacks;
  double last = -1.0;
  int cycles = 0;
  for (const SimulationInput& input : *log_) {
    if (input.kind != SimulationInput::Kind::cycle) continue;
    ++cycles;
    ASSERT_TRUE(std::isfinite(input.servo_time_s));
    EXPECT_GE(input.servo_time_s, last);
    last = input.servo_time_s;
  }
  EXPECT_GT(cycles, 20);
}

TEST_F(SessionReplayTest, ReplayedToTheEndItIsTheRunToTheLastBit) {
  SessionReplay replay(*scene_, *log_, live_->step_s());
  EXPECT_EQ(replay.time_s(), replay.begin_s());
  EXPECT_TRUE(replay.advance_to(replay.end_s()));
  EXPECT_TRUE(replay.at_end());
  EXPECT_EQ(replay.time_s(), replay.end_s());
  expect_the_run(replay.simulation());
}

TEST_F(SessionReplayTest, ReplayedAFewCyclesAtATimeItArrivesAtTheSameState) {
  SessionReplay replay(*scene_, *log_, live_->step_s());
  int calls = 0;
  double last = replay.time_s();
  while (!replay.advance_to(replay.end_s(), 3)) {
    ++calls;
    EXPECT_GE(replay.time_s(), last);
    last = replay.time_s();
    ASSERT_LT(calls, 100'000);
  }
  EXPECT_GT(calls, 5) << "three cycles a call took few calls: the log is too short to tell";
  expect_the_run(replay.simulation());
}

TEST_F(SessionReplayTest, ASeekBackStartsFromRestAndASeekOnGoesOnFromThere) {
  SessionReplay replay(*scene_, *log_, live_->step_s());
  const double middle = 0.5 * (replay.begin_s() + replay.end_s());
  replay.advance_to(middle);
  EXPECT_LE(replay.time_s(), middle);
  EXPECT_FALSE(replay.at_end());
  const NodeArray at_middle = replay.simulation().state().position_m;
  const std::uint64_t steps_at_middle = replay.simulation().state().step_count;
  EXPECT_LT(steps_at_middle, live_->state().step_count);
  // On to the end from the middle: the run.
  replay.advance_to(replay.end_s());
  expect_the_run(replay.simulation());
  // Back to the middle: from rest again, the same state as the first time there.
  replay.advance_to(middle);
  EXPECT_EQ(replay.simulation().state().step_count, steps_at_middle);
  EXPECT_TRUE(same_positions(replay.simulation().state().position_m, at_middle));
  // Before the first cycle: rest.
  replay.advance_to(replay.begin_s() - 1.0);
  EXPECT_EQ(replay.simulation().state().step_count, 0u);
}

TEST_F(SessionReplayTest, ALogOfAnotherModelOrWithoutTimedCyclesIsRefused) {
  SimulationInput far;
  far.kind = SimulationInput::Kind::springs;
  far.springs.push_back({static_cast<NodeIndex>(scene_->mesh.node_count() + 5), {0, 0, 0}, 1.0});
  const SimulationInput cycle{SimulationInput::Kind::cycle, std::nullopt, {}, 1, false, 1.0};
  SessionReplay replay(*scene_, {far, cycle}, live_->step_s());
  try {
    replay.advance_to(2.0);
    ADD_FAILURE() << "a spring on a node the model does not have was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("node " + std::to_string(scene_->mesh.node_count() + 5)),
              std::string::npos)
        << e.what();
  }
  const SimulationInput untimed{SimulationInput::Kind::cycle, std::nullopt, {}, 1, false};
  EXPECT_THROW(SessionReplay(*scene_, {untimed}, live_->step_s()), std::invalid_argument);
}

TEST(SessionReplayScene, FreePracticeIsTheBuiltInLiverAtItsCountWithTheSessionsIntegrator) {
  ReplaySetup setup;
  setup.built_in_liver_tets = 1500;
  setup.integrator.kind = IntegratorKind::bdf2;
  setup.integrator.step_s = 0.004;
  const SceneSetup scene = replay_scene(setup, "free practice");
  const SceneSetup reference = default_scene(1500);
  EXPECT_EQ(scene.mesh.tet_count(), reference.mesh.tet_count());
  EXPECT_TRUE(same_positions(scene.mesh.rest_position_m, reference.mesh.rest_position_m));
  EXPECT_EQ(scene.model_options.integrator.kind, IntegratorKind::bdf2);
  EXPECT_EQ(scene.model_options.integrator.step_s, 0.004);
  // A scenario that no longer reads is named as such.
  ReplaySetup from_scenario;
  try {
    replay_scene(from_scenario, "{ not json");
    ADD_FAILURE() << "a broken scenario text was built";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not read any more"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace liversim
