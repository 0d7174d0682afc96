// Stepping allocates nothing, and the real-time loop runs the liver off the caller's thread.
#include "liversim/engine/health.h"
#include "liversim/engine/integrator.h"
#include "liversim/engine/model_building.h"
#include "liversim/interaction/grab.h"
#include "liversim/interaction/tools.h"
#include "liversim/meshing/default_scene.h"
#include "liversim/meshing/liver_geometry.h"
#include "liversim/simulation/realtime_simulation.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>

namespace {
std::atomic<long> g_allocations{0};
}

// Counts every heap allocation made by any thread of this test program. Every form of the plain
// operators is replaced, so that what one form allocates another frees (libraries allocate with
// nothrow new and free with delete; a sanitizer build flags a mix of its operators and these).
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  ++g_allocations;
  return std::malloc(size ? size : 1);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept {
  return operator new(size, tag);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace liversim {
namespace {

struct SteppingFixture : ::testing::Test {
  static void SetUpTestSuite() {
    mesh_ = new TetMesh(generate_liver_mesh(3841).mesh);
    ModelOptions options;
    options.fixed_nodes = mesh_->node_sets.at("ligament");
    model_ = std::make_shared<const SimModel>(build_model(*mesh_, options));
  }
  static void TearDownTestSuite() {
    delete mesh_;
    model_.reset();
  }
  static TetMesh* mesh_;
  static std::shared_ptr<const SimModel> model_;
  std::shared_ptr<WorkerPool> workers_ = make_worker_pool(2);
};
TetMesh* SteppingFixture::mesh_ = nullptr;
std::shared_ptr<const SimModel> SteppingFixture::model_;

TEST_F(SteppingFixture, AdvanceAllocatesNothing) {
  SimState state = make_rest_state(*model_, workers_);
  const BoundarySurface surface = extract_surface(*mesh_);
  const Eigen::Vector3d point = mesh_->rest_position_m.at(surface.nodes[10]);
  const Grab grab =
      grab_surface(surface, state.position_m, model_->lumped_mass_kg, point, 0.015, 300.0);
  std::vector<NodeSpring> springs;
  grab_springs(grab, point + Eigen::Vector3d(0.01, 0.0, 0.0), springs);
  const std::vector<PointLoad> loads{{surface.nodes[20], Eigen::Vector3d(0.0, 0.05, 0.0)}};
  const StepInputs inputs{loads, springs};
  advance(*model_, state, inputs, 0.01);  // warm-up

  const long before = g_allocations.load();
  const StepReport report = advance(*model_, state, inputs, 0.05);
  const long allocations = g_allocations.load() - before;
  EXPECT_EQ(allocations, 0);
  EXPECT_GT(report.substeps, 1);
}

// Every integrator, viscous arm and sparse factorisation included, steps without allocating.
TEST_F(SteppingFixture, EveryIntegratorAdvancesWithoutAllocating) {
  for (IntegratorKind kind : kAllIntegrators) {
    ModelOptions options;
    options.fixed_nodes = mesh_->node_sets.at("ligament");
    options.regions[0].tissue = TissueMaterial{3500.0, 0.45, 1060.0};
    options.regions[0].viscoelastic = kSeedViscoelastic;
    options.regions[0].viscoplastic = ViscoplasticParameters{50.0, 500.0, 0.5};
    options.integrator.kind = kind;
    options.integrator.step_s = is_explicit(kind) ? 0.0 : 0.002;
    const SimModel model = build_model(*mesh_, options);
    // On two threads: the workers claim their chunks without allocating either.
    SimState state = make_rest_state(model, workers_);
    const std::vector<PointLoad> loads{{anterior_marked_node(*mesh_), {0.0, 0.05, 0.0}}};
    const StepInputs inputs{loads, {}};
    advance(model, state, inputs, 0.004);  // warm-up
    StateCheckpoint checkpoint = make_checkpoint(model);
    guarded_advance(model, state, inputs, 0.002, checkpoint);  // warm-up of the guard
    const long before = g_allocations.load();
    const StepReport report = advance(model, state, inputs, 0.01);
    // The guards too, a rollback included (a NaN written into the state).
    guarded_advance(model, state, inputs, 0.004, checkpoint);
    state.position_m.x[0] = std::nan("");
    const GuardedReport guarded = guarded_advance(model, state, inputs, 0.004, checkpoint);
    EXPECT_EQ(g_allocations.load() - before, 0) << integrator_name(kind);
    EXPECT_GT(report.substeps, 0);
    EXPECT_EQ(guarded.rollbacks, 1);
  }
}

TEST_F(SteppingFixture, RealtimeLoopFollowsTheDragAndAllocatesNothingWhileRunning) {
  RealtimeSimulation simulation(model_, make_rest_state(*model_, workers_));
  const BoundarySurface surface = extract_surface(*mesh_);
  const NodeIndex node = anterior_marked_node(*mesh_);
  ASSERT_FALSE(model_->is_fixed[node]);
  const Eigen::Vector3d rest = mesh_->rest_position_m.at(node);
  const Grab grab =
      grab_surface(surface, mesh_->rest_position_m, model_->lumped_mass_kg, rest, 0.012, 300.0);
  std::vector<NodeSpring> springs;
  grab_springs(grab, rest + Eigen::Vector3d(0.0, 0.0, 0.03), springs);
  simulation.set_springs(springs);
  simulation.start();

  // Wait for 0.6 s of simulated time (on a slow machine that may take longer than 0.6 s of wall).
  auto wait_for_sim_time = [&](double t_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline) {
      if (simulation.update_snapshot() && simulation.snapshot().time_s >= t_s) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  };
  ASSERT_TRUE(wait_for_sim_time(0.3));
  const long before = g_allocations.load();
  ASSERT_TRUE(wait_for_sim_time(0.6));
  EXPECT_EQ(g_allocations.load() - before, 0);

  const Eigen::Vector3d pulled = simulation.snapshot().position_m.at(node);
  EXPECT_GT(pulled.z() - rest.z(), 0.005);  // follows the handle 30 mm forward
  const RealtimeStats stats = simulation.stats();
  EXPECT_GT(stats.steps_per_second, 0.0);
  EXPECT_GT(stats.real_time_factor, 0.0);

  simulation.clear_springs();
  const double released_at = simulation.snapshot().time_s;
  ASSERT_TRUE(wait_for_sim_time(released_at + 2.0));
  simulation.stop();
  // Springs back: the mass damping (α = 8/s) leaves e^(−8) of the amplitude after 2 s.
  EXPECT_LT((simulation.snapshot().position_m.at(node) - rest).norm(), 0.001);
}

// A tool's interval allocates nothing either (issue 7): contact, the forceps closing on the tissue
// (the hold's buffers are sized for the whole surface), holding, and letting go.
TEST_F(SteppingFixture, ToolIntervalsAllocateNothingEvenWhenTheJawsClose) {
  SimState state = make_rest_state(*model_, workers_);
  ToolInteraction hand(*model_, extract_surface(*mesh_));
  const NodeIndex node = anterior_marked_node(*mesh_);
  Tool forceps;
  forceps.kind = ToolKind::forceps;
  forceps.jaw_opening = 1.0;
  forceps.pose.origin_m =
      mesh_->rest_position_m.at(node) - (forceps_grasp_point_m(forceps) - forceps.pose.origin_m);
  advance(*model_, state, {{}, hand.update(forceps, state.position_m)}, 1e-3);  // warm-up
  const long before = g_allocations.load();
  for (int interval = 0; interval < 40; ++interval) {
    forceps.jaw_opening = interval < 10 ? 1.0 : interval < 30 ? 0.0 : 1.0;
    advance(*model_, state, {{}, hand.update(forceps, state.position_m)}, 1e-3);
    if (interval == 10) {
      EXPECT_TRUE(hand.grasping());
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_FALSE(hand.grasping());
}

}  // namespace
}  // namespace liversim
