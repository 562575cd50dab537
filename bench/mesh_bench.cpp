// Suite `mesh`: the core mesh kernel on the real VHF gluteus maximus
// (48K triangles, the largest muscle of the atlas). Run with `bench/run mesh`.
//
// Query benchmarks time one batch per iteration (1e6 closest points, 1e5
// inside tests / signed distances) over fixed random points spread through
// the mesh's bounding box enlarged by 20%, so that a third or so fall inside.

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <random>

#include "core/mesh/aabb_tree.h"
#include "core/mesh/decimate.h"
#include "core/mesh/io/mesh_io.h"
#include "core/mesh/mass_properties.h"
#include "core/mesh/mesh_check.h"
#include "core/mesh/signed_distance.h"
#include "core/mesh/winding_number.h"

namespace {

using mmm::mesh::IndexedMesh;

std::filesystem::path gluteus_maximus_path() {
  const char* override_dir = std::getenv("MMM_DATA_DIR");
  const std::filesystem::path data = override_dir != nullptr ? override_dir : MMM_DATA_DIR;
  return data / "vhf" / "Right" / "VHF_Right_Muscle_GluteusMaximus_smooth.stl";
}

const IndexedMesh& gluteus_maximus() {
  static const IndexedMesh mesh = mmm::mesh::read_mesh(gluteus_maximus_path());
  return mesh;
}

const mmm::mesh::SignedDistance& gluteus_distance() {
  static const mmm::mesh::SignedDistance distance(gluteus_maximus());
  return distance;
}

Eigen::MatrixX3d random_points(Eigen::Index count) {
  const Eigen::AlignedBox3d box = mmm::mesh::bounding_box(gluteus_maximus());
  const Eigen::Vector3d center = box.center();
  const Eigen::Vector3d half = 0.6 * box.sizes();
  std::mt19937_64 generator(20261122);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::MatrixX3d points(count, 3);
  for (Eigen::Index i = 0; i < count; ++i) {
    for (int k = 0; k < 3; ++k) points(i, k) = center[k] + half[k] * unit(generator);
  }
  return points;
}

void BM_ReadStl(benchmark::State& state) {
  const auto path = gluteus_maximus_path();
  for (auto _ : state) benchmark::DoNotOptimize(mmm::mesh::read_mesh(path));
  state.counters["faces"] = static_cast<double>(gluteus_maximus().num_faces());
}
BENCHMARK(BM_ReadStl)->Unit(benchmark::kMillisecond);

void BM_BvhBuild(benchmark::State& state) {
  const IndexedMesh& mesh = gluteus_maximus();
  for (auto _ : state) benchmark::DoNotOptimize(mmm::mesh::AabbTree(mesh));
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());
}
BENCHMARK(BM_BvhBuild)->Unit(benchmark::kMillisecond);

void BM_ClosestPoint1e6(benchmark::State& state) {
  const mmm::mesh::AabbTree& tree = gluteus_distance().tree();
  const Eigen::MatrixX3d points = random_points(1'000'000);
  for (auto _ : state) {
    double sum = 0;
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      sum += tree.closest_point(points.row(i).transpose()).squared_distance;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * points.rows());
}
BENCHMARK(BM_ClosestPoint1e6)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_InsideTest1e5(benchmark::State& state) {
  const mmm::mesh::WindingNumber& winding = gluteus_distance().winding();
  const Eigen::MatrixX3d points = random_points(100'000);
  for (auto _ : state) {
    int inside = 0;
    for (Eigen::Index i = 0; i < points.rows(); ++i) {
      inside += winding.is_inside(points.row(i).transpose()) ? 1 : 0;
    }
    benchmark::DoNotOptimize(inside);
    state.counters["inside_fraction"] = static_cast<double>(inside) / points.rows();
  }
  state.SetItemsProcessed(state.iterations() * points.rows());
}
BENCHMARK(BM_InsideTest1e5)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_SignedDistance1e5(benchmark::State& state) {
  const mmm::mesh::SignedDistance& distance = gluteus_distance();
  const Eigen::MatrixX3d points = random_points(100'000);
  for (auto _ : state) benchmark::DoNotOptimize(distance.at(points));
  state.SetItemsProcessed(state.iterations() * points.rows());
}
BENCHMARK(BM_SignedDistance1e5)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_Volume(benchmark::State& state) {
  const IndexedMesh& mesh = gluteus_maximus();
  for (auto _ : state) benchmark::DoNotOptimize(mmm::mesh::signed_volume(mesh));
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());
}
BENCHMARK(BM_Volume)->Unit(benchmark::kMicrosecond);

void BM_MeshCheck(benchmark::State& state) {
  const IndexedMesh& mesh = gluteus_maximus();
  for (auto _ : state) benchmark::DoNotOptimize(mmm::mesh::check_mesh(mesh));
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());
}
BENCHMARK(BM_MeshCheck)->Unit(benchmark::kMillisecond);

void BM_DecimateTo5000(benchmark::State& state) {
  const IndexedMesh& mesh = gluteus_maximus();
  for (auto _ : state) {
    benchmark::DoNotOptimize(mmm::mesh::decimate(mesh, {.target_faces = 5000}));
  }
  state.SetItemsProcessed(state.iterations() * mesh.num_faces());
}
BENCHMARK(BM_DecimateTo5000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
