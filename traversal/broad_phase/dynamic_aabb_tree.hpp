// DynamicAabbTree: a binary tree over the object boxes, kept across frames; its shape changes only where
// objects left their fattened boxes, and its boxes are refitted to the objects' own boxes every frame.
//
// Fattening: each object keeps a fat box, its box grown on every side by
//     margin = relative_margin * (largest side of the object's box) + absolute_margin
// (defaults 0.1 and 0: a tenth of the object's size, with no unit-dependent constant). While the object's
// box stays inside that fat box, its leaf keeps its place in the tree (one containment test); once it
// leaves, it gets a fresh fat box and its leaf a new place (reinsertions() counts those).
//
// The leaves and inner nodes hold tight boxes, refitted bottom-up every frame (a pass over the nodes): the
// pair traversal then tests no more overlaps than the objects' boxes make, where fat node boxes made about
// twice the leaf pairs in a dense world. Refitting every frame is what a fat tree's skipped updates save,
// but it costs less than the fat boxes' extra traversal on the scenes measured (the table in
// traversal/broad_phase/README.md).
//
// Registration builds the tree over the leaves in Morton order. A frame in which more than a quarter of the
// objects left their fat boxes (reinserting most leaves one by one costs more than building anew) keeps the
// shape as it stands, which stays good under coherent motion; otherwise the leavers are removed and
// reinserted one by one. Insertion descends from the root by a surface-area cost: at each inner node it
// compares making a new parent of the leaf and this node (twice the merged box's area) with descending into
// either child (the child's area growth, plus the growth every ancestor on the way already pays). That is
// the greedy surface-area heuristic; it keeps boxes that are near each other under one parent. Every
// ancestor of a changed leaf is then refitted and, where its children's heights differ by more than one,
// rotated (the taller child moves up, AVL style), so the height stays O(log n) whatever the insertion order.
// After the refit, the tree is rebuilt as at registration when its inner boxes' total area, relative to the
// leaves', has grown by kRefitSlack (1.25) since the last build.
//
// Pairs: one self traversal of the tree per frame (a node with itself: its two children with each other
// and each with itself; two nodes: descend the taller while their boxes touch). Two leaves whose boxes touch
// are a pair, so pairs() is exactly the overlapping tight boxes, as for the other broad phases.
#pragma once

#include "broad_phase.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <utility>

namespace bvhlab {

class DynamicAabbTree {
 public:
  struct Options {
    double relative_margin = 0.1;  ///< fraction of the object box's largest side added on every side
    double absolute_margin = 0;    ///< added on every side, in the scene's units
  };

  DynamicAabbTree() = default;
  explicit DynamicAabbTree(const Options& options) : options_(options) {
    if (!(options.relative_margin >= 0 && options.absolute_margin >= 0 &&
          std::isfinite(options.relative_margin) && std::isfinite(options.absolute_margin)))
      throw std::invalid_argument("dynamic_aabb_tree: margins must be finite and non-negative");
  }

  static constexpr std::string_view name() { return "dynamic_aabb_tree"; }

  void update(std::span<const Box> boxes) {
    broad_phase_detail::check_update(name(), boxes, registered_);
    tight_ = boxes;  // read during this update only: not copied
    if (registered_ < 0) {
      registered_ = static_cast<std::int64_t>(boxes.size());
      register_objects();
    } else {
      moved_.clear();
      for (std::uint32_t i = 0; i < leaf_of_.size(); ++i)
        if (!contains(fat_[i], tight_[i])) moved_.push_back(i);
      last_reinsertions_ = moved_.size();
      reinsertions_ += last_reinsertions_;
      for (std::uint32_t i : moved_) fat_[i] = fattened(tight_[i]);
      // Most objects moved (coherent motion of everything): keep the shape, the refit below places them.
      if (moved_.size() <= kRebuildShare * double(leaf_of_.size()))
        for (std::uint32_t i : moved_) {
          const std::int32_t leaf = leaf_of_[i];
          remove_leaf(leaf);
          nodes_[leaf].box = NodeBox::around(tight_[i]);
          insert_leaf(leaf);
        }
      refit_all();
    }
    find_pairs();
    tight_ = {};
  }

  [[nodiscard]] const std::vector<ObjectPair>& pairs() const { return pairs_; }

  /// Objects that left their fat boxes since registration (each got a new fat box and its leaf a new place:
  /// reinserted, or kept and refitted in a frame where most objects left theirs).
  [[nodiscard]] std::uint64_t reinsertions() const { return reinsertions_; }
  /// The same, in the last update only.
  [[nodiscard]] std::uint64_t last_reinsertions() const { return last_reinsertions_; }
  /// Frames after registration whose tree was refitted and kept, not rebuilt.
  [[nodiscard]] std::uint64_t refits() const { return refits_; }
  /// Edges on the longest root-to-leaf path (0 for a single leaf or none).
  [[nodiscard]] int height() const { return root_ == kNull ? 0 : nodes_[root_].height; }
  /// Object i's fat box: while its box stays inside, its leaf keeps its place.
  [[nodiscard]] const Box& fat_box(std::uint32_t object) const { return fat_.at(object); }
  [[nodiscard]] const Options& options() const { return options_; }

 private:
  static constexpr std::int32_t kNull = -1;
  /// When more than this share of the objects left their fat boxes in one frame, the tree is refitted or
  /// rebuilt instead of reinserting them one by one.
  static constexpr double kRebuildShare = 0.25;
  /// How much the inner boxes' total area (relative to the leaves') may grow under refits before a rebuild.
  static constexpr double kRefitSlack = 1.25;

  // Leaves have left == kNull and keep their object in `right`.
  // A node's box in floats rounded outwards, four lanes a corner (the fourth 0 in both, so it always
  // passes): 32 bytes, tested in two vector comparisons. The pair traversal's time is mostly its loads, and
  // this halves them (13% less time in a dense world than double boxes). Leaf pairs are confirmed on the
  // objects' own boxes, so the rounding never adds a pair.
  struct alignas(16) NodeBox {
    float lo[4] = {0, 0, 0, 0};
    float hi[4] = {0, 0, 0, 0};

    static NodeBox around(const Box& b) {
      NodeBox out;
      for (int k = 0; k < 3; ++k) {
        out.lo[k] = below(b.min[k]);
        out.hi[k] = -below(-b.max[k]);
      }
      return out;
    }
    // A float <= x, without branches: x moved down by more than rounding to the nearest float can move it
    // back up (half an ulp: 2^-24 relative, or 2^-150 among subnormals), then rounded. Monotone in x, and
    // -below(-x) >= x, so boxes that touch keep touching; beyond the float range lo and hi go to infinity.
    static float below(double x) { return static_cast<float>(x - std::abs(x) * 0x1p-22 - 0x1p-148); }
    static NodeBox merged(const NodeBox& a, const NodeBox& b) {
      NodeBox out;
      for (int k = 0; k < 4; ++k) {
        out.lo[k] = std::min(a.lo[k], b.lo[k]);
        out.hi[k] = std::max(a.hi[k], b.hi[k]);
      }
      return out;
    }
    [[nodiscard]] double half_area() const {
      const double x = double(hi[0]) - lo[0], y = double(hi[1]) - lo[1], z = double(hi[2]) - lo[2];
      return x * y + y * z + z * x;
    }
    static bool touch(const NodeBox& a, const NodeBox& b) {
#if defined(__SSE2__)
      const __m128 a_lo = _mm_load_ps(a.lo), a_hi = _mm_load_ps(a.hi);
      const __m128 b_lo = _mm_load_ps(b.lo), b_hi = _mm_load_ps(b.hi);
      return _mm_movemask_ps(_mm_and_ps(_mm_cmple_ps(a_lo, b_hi), _mm_cmple_ps(b_lo, a_hi))) == 0xF;
#else
      return broad_phase_detail::all_hold(a.lo[0] <= b.hi[0], b.lo[0] <= a.hi[0], a.lo[1] <= b.hi[1],
                                          b.lo[1] <= a.hi[1], a.lo[2] <= b.hi[2], b.lo[2] <= a.hi[2]);
#endif
    }
  };

  struct Node {
    NodeBox box;
    std::int32_t parent = kNull;
    std::int32_t left = kNull;
    std::int32_t right = kNull;
    std::int32_t height = 0;
  };

  [[nodiscard]] bool is_leaf(std::int32_t i) const {
    return nodes_[i].left == kNull;
  }

  static bool contains(const Box& outer, const Box& inner) {
    // Not short-circuited: under motion the six outcomes are mixed (half the time of this test on 1,000
    // moving objects went to mispredicted branches).
    return broad_phase_detail::all_hold(outer.min.x() <= inner.min.x(), outer.min.y() <= inner.min.y(),
                                        outer.min.z() <= inner.min.z(), inner.max.x() <= outer.max.x(),
                                        inner.max.y() <= outer.max.y(), inner.max.z() <= outer.max.z());
  }

  [[nodiscard]] Box fattened(const Box& b) const {
    const Vec3 side = b.max - b.min;
    const double margin = options_.relative_margin * std::max(std::max(side.x(), side.y()), side.z()) +
                          options_.absolute_margin;
    return {b.min.array() - margin, b.max.array() + margin};
  }

  std::int32_t allocate() {
    if (!free_.empty()) {
      const std::int32_t i = free_.back();
      free_.pop_back();
      nodes_[i] = Node{};
      return i;
    }
    nodes_.emplace_back();
    return static_cast<std::int32_t>(nodes_.size() - 1);
  }

  void register_objects() {
    nodes_.assign(tight_.size(), Node{});
    leaf_of_.resize(tight_.size());
    fat_.resize(tight_.size());
    for (std::uint32_t i = 0; i < tight_.size(); ++i) {
      nodes_[i].box = NodeBox::around(tight_[i]);
      fat_[i] = fattened(tight_[i]);
      nodes_[i].right = static_cast<std::int32_t>(i);
      leaf_of_[i] = static_cast<std::int32_t>(i);
    }
    rebuild();
  }

  // Drops every inner node and builds them again over the leaves as they are: the leaves sorted along a
  // Morton (Z-order) curve through their centres (21 bits an axis over the centres' bounds), each range
  // split where its codes' highest differing bit changes, i.e. on a plane of the implicit octree. O(n log n)
  // for the sort and little else: far cheaper than reinserting most leaves one by one. The height is at most
  // 63 plus log2 of the largest group of coincident centres.
  void rebuild() {
    const std::size_t n = leaf_of_.size();
    nodes_.resize(n);  // leaves are nodes 0 .. n-1 (register_objects), inner nodes follow
    free_.clear();
    root_ = kNull;
    if (n == 0) return;
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 c = centre(i);
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    constexpr double kCells = (1 << 21) - 1;  // 21 bits per axis: a 63-bit code
    const Vec3 scale = kCells * (hi - lo).cwiseMax(Vec3::Constant(1e-300)).cwiseInverse();
    items_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 cell = ((centre(i) - lo).cwiseProduct(scale)).cwiseMin(kCells);
      items_[i] = {spread_bits(std::uint64_t(cell.x())) | spread_bits(std::uint64_t(cell.y())) << 1 |
                       spread_bits(std::uint64_t(cell.z())) << 2,
                   static_cast<std::int32_t>(i)};
    }
    std::sort(items_.begin(), items_.end(), [](const Item& a, const Item& b) { return a.code < b.code; });
    nodes_.reserve(2 * n);
    root_ = build_range(0, n);
    nodes_[root_].parent = kNull;
    double leaves = 0;
    const double inner = subtree_area(root_, leaves);
    built_quality_ = leaves > 0 ? inner / leaves : 0;
  }

  // Every leaf to its object's box, every inner node refitted; rebuilt if the shape has grown poor.
  void refit_all() {
    if (root_ == kNull) return;
    for (std::uint32_t i = 0; i < leaf_of_.size(); ++i) nodes_[leaf_of_[i]].box = NodeBox::around(tight_[i]);
    double leaves = 0;
    const double inner = refit_subtree(root_, leaves);
    if (inner > kRefitSlack * built_quality_ * leaves)
      rebuild();
    else
      ++refits_;
  }

  // Sum of the inner nodes' half areas below i (and of the leaves' into `leaves`), refitting on the way.
  double refit_subtree(std::int32_t i, double& leaves) {
    Node& n = nodes_[i];
    if (n.left == kNull) {
      leaves += n.box.half_area();
      return 0;
    }
    const double below = refit_subtree(n.left, leaves) + refit_subtree(n.right, leaves);
    n.box = NodeBox::merged(nodes_[n.left].box, nodes_[n.right].box);
    return below + n.box.half_area();
  }
  // The same without refitting.
  double subtree_area(std::int32_t i, double& leaves) const {
    const Node& n = nodes_[i];
    if (n.left == kNull) {
      leaves += n.box.half_area();
      return 0;
    }
    return subtree_area(n.left, leaves) + subtree_area(n.right, leaves) + n.box.half_area();
  }

  // The centre of leaf i's object, from its own box: finite, where a rounded box may not be.
  [[nodiscard]] Vec3 centre(std::size_t leaf) const {
    const Box& b = tight_[static_cast<std::size_t>(nodes_[leaf].right)];
    return 0.5 * b.min + 0.5 * b.max;
  }

  // The 21 low bits of x moved to every third bit (bit k to bit 3k).
  static std::uint64_t spread_bits(std::uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
  }

  std::int32_t build_range(std::size_t begin, std::size_t end) {
    if (end - begin == 1) return items_[begin].node;
    // Split where the highest bit in which the range's codes differ turns on: a plane of the implicit
    // octree, so each child is one spatial cell. Equal codes (coincident centres) split in the middle.
    std::size_t middle = begin + (end - begin) / 2;
    const std::uint64_t first = items_[begin].code, last = items_[end - 1].code;
    if (first != last) {
      const std::uint64_t bit = std::uint64_t(1) << (63 - std::countl_zero(first ^ last));
      middle = static_cast<std::size_t>(
          std::partition_point(items_.begin() + begin, items_.begin() + end,
                               [bit](const Item& item) { return (item.code & bit) == 0; }) -
          items_.begin());
    }
    const std::int32_t left = build_range(begin, middle), right = build_range(middle, end);
    // Appended whole (the free list is empty during a rebuild): no default box written and overwritten.
    const auto parent = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back({NodeBox::merged(nodes_[left].box, nodes_[right].box), kNull, left, right,
                      1 + std::max(nodes_[left].height, nodes_[right].height)});
    nodes_[left].parent = parent;
    nodes_[right].parent = parent;
    return parent;
  }

  // The sibling the surface-area heuristic picks for a new leaf with box b.
  [[nodiscard]] std::int32_t choose_sibling(const NodeBox& b) const {
    std::int32_t i = root_;
    double inherited = 0;  // area growth of the ancestors already passed
    while (!is_leaf(i)) {
      const Node& n = nodes_[i];
      const double area = n.box.half_area(), combined = NodeBox::merged(n.box, b).half_area();
      const double here = combined + inherited;  // a new parent of i and the leaf
      inherited += combined - area;
      auto descend_cost = [&](std::int32_t c) {
        const double grown = NodeBox::merged(nodes_[c].box, b).half_area();
        return (is_leaf(c) ? grown : grown - nodes_[c].box.half_area()) + inherited;
      };
      const double left = descend_cost(n.left), right = descend_cost(n.right);
      if (here <= left && here <= right) break;
      i = left <= right ? n.left : n.right;
    }
    return i;
  }

  void insert_leaf(std::int32_t leaf) {
    if (root_ == kNull) {
      root_ = leaf;
      nodes_[leaf].parent = kNull;
      return;
    }
    const std::int32_t sibling = choose_sibling(nodes_[leaf].box);
    const std::int32_t old_parent = nodes_[sibling].parent;
    const std::int32_t parent = allocate();  // may reallocate nodes_: no references held across it
    nodes_[parent].parent = old_parent;
    nodes_[parent].left = sibling;
    nodes_[parent].right = leaf;
    replace_child(old_parent, sibling, parent);
    nodes_[sibling].parent = parent;
    nodes_[leaf].parent = parent;
    refit_upwards(parent);
  }

  void remove_leaf(std::int32_t leaf) {
    if (leaf == root_) {
      root_ = kNull;
      return;
    }
    const std::int32_t parent = nodes_[leaf].parent;
    const std::int32_t grand = nodes_[parent].parent;
    const std::int32_t sibling = nodes_[parent].left == leaf ? nodes_[parent].right : nodes_[parent].left;
    replace_child(grand, parent, sibling);
    nodes_[sibling].parent = grand;
    free_.push_back(parent);
    nodes_[leaf].parent = kNull;
    if (grand != kNull) refit_upwards(grand);
  }

  // In `parent` (or at the root when parent is kNull), `from` becomes `to`.
  void replace_child(std::int32_t parent, std::int32_t from, std::int32_t to) {
    if (parent == kNull)
      root_ = to;
    else if (nodes_[parent].left == from)
      nodes_[parent].left = to;
    else
      nodes_[parent].right = to;
  }

  void refit(std::int32_t i) {
    Node& n = nodes_[i];
    n.box = NodeBox::merged(nodes_[n.left].box, nodes_[n.right].box);
    n.height = 1 + std::max(nodes_[n.left].height, nodes_[n.right].height);
  }

  void refit_upwards(std::int32_t i) {
    while (i != kNull) {
      i = rebalance(i);
      refit(i);
      i = nodes_[i].parent;
    }
  }

  // If one child of i is more than one level taller than the other, the taller child takes i's place, i
  // keeps the shorter child and the shorter of the taller one's children. Returns the node now at i's place.
  std::int32_t rebalance(std::int32_t i) {
    const std::int32_t l = nodes_[i].left, r = nodes_[i].right;
    const std::int32_t skew = nodes_[r].height - nodes_[l].height;
    if (skew >= -1 && skew <= 1) return i;
    const bool right_heavy = skew > 1;
    const std::int32_t up = right_heavy ? r : l;
    const std::int32_t f = nodes_[up].left, g = nodes_[up].right;
    const bool keep_f = nodes_[f].height > nodes_[g].height;
    const std::int32_t keep = keep_f ? f : g, give = keep_f ? g : f;

    replace_child(nodes_[i].parent, i, up);
    nodes_[up].parent = nodes_[i].parent;
    nodes_[up].left = i;
    nodes_[up].right = keep;
    nodes_[i].parent = up;
    (right_heavy ? nodes_[i].right : nodes_[i].left) = give;
    nodes_[give].parent = i;
    refit(i);
    refit(up);
    return up;
  }

  void find_pairs() {
    pairs_.clear();
    if (root_ == kNull) return;
    // Depth first, each pop pushes at most three pairs and each push goes a level deeper on one side, so
    // the stack never holds more than 2 (2 height + 1) + 3 pairs: a fixed buffer, no growth checks.
    stack_.resize(4 * static_cast<std::size_t>(nodes_[root_].height) + 8);
    std::pair<std::int32_t, std::int32_t>* stack = stack_.data();
    std::size_t top = 0;
    // A pair is pushed only once its boxes are known to touch (a node with itself always does), so most
    // separated pairs cost one test and no stack traffic.
    auto touch = [this](std::int32_t x, std::int32_t y) {
      return NodeBox::touch(nodes_[x].box, nodes_[y].box);
    };
    if (nodes_[root_].left != kNull) stack[top++] = {root_, root_};
    while (top > 0) {
      const auto [a, b] = stack[--top];
      const Node& na = nodes_[a];
      if (a == b) {  // an inner node with itself
        if (nodes_[na.left].left != kNull) stack[top++] = {na.left, na.left};
        if (nodes_[na.right].left != kNull) stack[top++] = {na.right, na.right};
        if (touch(na.left, na.right)) stack[top++] = {na.left, na.right};
        continue;
      }
      const Node& nb = nodes_[b];
      const bool a_leaf = na.left == kNull, b_leaf = nb.left == kNull;
      if (a_leaf && b_leaf) {  // their rounded boxes touch; the objects' own decide
        const auto oa = static_cast<std::uint32_t>(na.right), ob = static_cast<std::uint32_t>(nb.right);
        if (broad_phase_detail::boxes_touch(tight_[oa], tight_[ob]))
          pairs_.push_back(broad_phase_detail::ordered_pair(oa, ob));
      } else if (b_leaf || (!a_leaf && na.height >= nb.height)) {
        if (touch(na.left, b)) stack[top++] = {na.left, b};
        if (touch(na.right, b)) stack[top++] = {na.right, b};
      } else {
        if (touch(a, nb.left)) stack[top++] = {a, nb.left};
        if (touch(a, nb.right)) stack[top++] = {a, nb.right};
      }
    }
    sorter_.sort(pairs_, leaf_of_.size());
  }

  Options options_{};
  std::int64_t registered_ = -1;
  std::vector<Node> nodes_;
  std::vector<std::int32_t> free_;
  std::vector<std::int32_t> leaf_of_;  // object -> its leaf
  std::vector<Box> fat_;               // object -> its fat box
  std::span<const Box> tight_;         // the object boxes of the update in progress
  std::int32_t root_ = kNull;
  std::uint64_t reinsertions_ = 0;
  std::uint64_t last_reinsertions_ = 0;
  std::uint64_t refits_ = 0;
  double built_quality_ = 0;  // inner / leaf area right after the last rebuild
  std::vector<std::pair<std::int32_t, std::int32_t>> stack_;
  std::vector<std::uint32_t> moved_;  // objects outside their fat boxes this frame
  struct Item {
    std::uint64_t code;  // Morton code of the leaf's centre
    std::int32_t node;
  };
  std::vector<Item> items_;  // rebuild: the leaves in Morton order
  std::vector<ObjectPair> pairs_;
  broad_phase_detail::PairSorter sorter_;
};

static_assert(BroadPhase<DynamicAabbTree>);

}  // namespace bvhlab
