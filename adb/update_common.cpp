#include "adb/update_common.hpp"

#include "adb/update.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace bvhlab {

CountError count_error(const AdbStorage& counts, const AdbStorage& exact) {
  const auto& c = counts.possible_collision_cells;
  const auto& e = exact.possible_collision_cells;
  if (c.size() != e.size())
    throw std::invalid_argument("count_error: " + std::to_string(c.size()) + " counts against " +
                                std::to_string(e.size()) + " exact ones");
  if (c.empty()) return {};
  double sum = 0;
  std::size_t under = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    sum += std::abs(int(c[i]) - int(e[i]));
    under += c[i] < e[i];
  }
  return {sum / double(c.size()), double(under) / double(c.size())};
}

namespace density_update {

void check_tree(std::string_view policy, std::size_t state_nodes, std::size_t tree_nodes,
                std::size_t storage_counts) {
  const std::string who = "density update '" + std::string(policy) + "': ";
  if (tree_nodes != state_nodes)
    throw std::invalid_argument(who + "the state was started on a tree of " + std::to_string(state_nodes) +
                                " nodes, this tree has " + std::to_string(tree_nodes));
  if (storage_counts != tree_nodes)
    throw std::invalid_argument(who + "the annotation holds " + std::to_string(storage_counts) +
                                " counts for a tree of " + std::to_string(tree_nodes) + " nodes");
}

AnnotateStats recount(std::span<const Box> boxes, const NodeRanges& ranges,
                      std::span<const TrianglePoints> triangles, std::span<const std::uint32_t> selected,
                      AdbStorage& storage, const AnnotationContext& context,
                      std::span<const OrientedBox> frames) {
  if (selected.empty()) return {};
  // annotate_counts takes any list of (box, triangle range): the selected nodes, compacted.
  std::vector<Box> chosen_boxes;
  std::vector<OrientedBox> chosen_frames;
  NodeRanges chosen_ranges;
  chosen_boxes.reserve(selected.size());
  chosen_ranges.reserve(selected.size());
  for (const std::uint32_t node : selected) {
    chosen_boxes.push_back(boxes[node]);
    if (!frames.empty()) chosen_frames.push_back(frames[node]);
    chosen_ranges.push_back(ranges[node]);
  }
  AnnotateOptions options;
  options.tau = storage.params.tau;
  options.threads = context.threads;
  options.progress = context.progress;
  CellCounts result =
      frames.empty()
          ? annotate_counts(chosen_boxes, chosen_ranges, triangles, storage.params.grid, options)
          : annotate_counts_in_frames(chosen_frames, chosen_ranges, triangles, storage.params.grid, options);
  for (std::size_t k = 0; k < selected.size(); ++k)
    storage.possible_collision_cells[selected[k]] = result.counts[k];
  return result.stats;
}

}  // namespace density_update
}  // namespace bvhlab
