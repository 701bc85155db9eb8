// nanoflann 1.4.3 (the pre-1.5 API Debian 12 ships) behind a small interface.
#include "engine/discretization/neighbor_search.hpp"

#include <algorithm>
#include <nanoflann.hpp>

namespace dhpd {
namespace {

struct PointCloud {
  const VectorArray* points;
  std::size_t kdtree_get_point_count() const { return (*points)[0].size(); }
  double kdtree_get_pt(std::size_t i, std::size_t axis) const { return (*points)[axis][i]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

template <int Dim>
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>,
                                                 PointCloud, Dim, std::size_t>;
}  // namespace

struct NeighborSearch::Impl {
  PointCloud cloud;
  int dim;
  std::unique_ptr<Tree<1>> t1;
  std::unique_ptr<Tree<2>> t2;
  std::unique_ptr<Tree<3>> t3;
};

NeighborSearch::NeighborSearch(const VectorArray& points, int dim)
    : impl_(std::make_unique<Impl>()) {
  impl_->cloud.points = &points;
  impl_->dim = dim;
  const nanoflann::KDTreeSingleIndexAdaptorParams params(16);
  if (dim == 1) impl_->t1 = std::make_unique<Tree<1>>(1, impl_->cloud, params);
  if (dim == 2) impl_->t2 = std::make_unique<Tree<2>>(2, impl_->cloud, params);
  if (dim == 3) impl_->t3 = std::make_unique<Tree<3>>(3, impl_->cloud, params);
  if (impl_->t1) impl_->t1->buildIndex();
  if (impl_->t2) impl_->t2->buildIndex();
  if (impl_->t3) impl_->t3->buildIndex();
}

NeighborSearch::~NeighborSearch() = default;

namespace {
/// Indices within `radius` of q, but `skip`, sorted ascending.
template <class Impl>
void search_around(const Impl& impl, const double q[3], double radius, std::size_t skip,
                   std::vector<std::int32_t>& out) {
  thread_local std::vector<std::pair<std::size_t, double>> matches;
  matches.clear();
  const double r2 = radius * radius;
  const nanoflann::SearchParams params(32, 0.0f, false);
  if (impl.t1) impl.t1->radiusSearch(q, r2, matches, params);
  if (impl.t2) impl.t2->radiusSearch(q, r2, matches, params);
  if (impl.t3) impl.t3->radiusSearch(q, r2, matches, params);
  out.clear();
  for (const auto& m : matches)
    if (m.first != skip) out.push_back(static_cast<std::int32_t>(m.first));
  std::sort(out.begin(), out.end());
}
}  // namespace

void NeighborSearch::within(std::size_t i, double radius, std::vector<std::int32_t>& out) const {
  const auto& p = *impl_->cloud.points;
  const double q[3] = {p[0][i], p[1][i], p[2][i]};
  search_around(*impl_, q, radius, i, out);
}

void NeighborSearch::around(const double x[3], double radius,
                            std::vector<std::int32_t>& out) const {
  search_around(*impl_, x, radius, static_cast<std::size_t>(-1), out);
}

}  // namespace dhpd
