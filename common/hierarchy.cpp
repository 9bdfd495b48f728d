#include "common/hierarchy.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace cl {

std::vector<int> coarser_lines(int count) {
  if (count < 3) {
    throw std::invalid_argument("coarser_lines: needs at least 3 grid lines (got " + std::to_string(count) + ")");
  }
  std::vector<int> kept;
  for (int line = 0; line < count; line += 2) kept.push_back(line);
  if (kept.back() != count - 1) kept.push_back(count - 1);
  return kept;
}

int max_levels(int nx, int ny) {
  int levels = 1;
  while (nx >= 3 && ny >= 3) {
    nx = static_cast<int>(coarser_lines(nx).size());
    ny = static_cast<int>(coarser_lines(ny).size());
    ++levels;
  }
  return levels;
}

namespace {

// One direction of the prolongation: a finer line at cloth index `line` lies on
// a coarse line (one parent, weight 1) or between two (weights by distance).
struct LineParents {
  int count = 1;
  int index[2] = {0, 0};  // positions in the coarse list of lines
  double weight[2] = {1.0, 0.0};
};

LineParents line_parents(int line, const std::vector<int>& coarse_lines) {
  LineParents result;
  const auto upper = std::lower_bound(coarse_lines.begin(), coarse_lines.end(), line);
  const int hi = static_cast<int>(upper - coarse_lines.begin());
  if (*upper == line) {
    result.index[0] = hi;
    return result;
  }
  const int lo = hi - 1;  // the first line is always kept, so lo >= 0
  const double t = static_cast<double>(line - coarse_lines[static_cast<std::size_t>(lo)]) /
                   static_cast<double>(coarse_lines[static_cast<std::size_t>(hi)] -
                                       coarse_lines[static_cast<std::size_t>(lo)]);
  result.count = 2;
  result.index[0] = lo;
  result.index[1] = hi;
  result.weight[0] = 1.0 - t;
  result.weight[1] = t;
  return result;
}

std::vector<int> pick(const std::vector<int>& lines, const std::vector<int>& positions) {
  std::vector<int> picked;
  for (const int p : positions) picked.push_back(lines[static_cast<std::size_t>(p)]);
  return picked;
}

void add_coarse_spring(HierarchyLevel& level, const Eigen::Matrix3Xd& rest, int i, int j) {
  level.springs.push_back(Spring{i, j, (rest.col(i) - rest.col(j)).norm(), kInfiniteStiffness});
}

}  // namespace

ClothHierarchy build_cloth_hierarchy(int nx, int ny, const Eigen::Matrix3Xd& rest_positions,
                                     const Eigen::VectorXd& inv_mass, const std::vector<Spring>& springs,
                                     int levels) {
  if (nx < 2 || ny < 2) {
    throw std::invalid_argument("build_cloth_hierarchy: the grid must be at least 2 x 2 (got " +
                                std::to_string(nx) + " x " + std::to_string(ny) + ")");
  }
  const Eigen::Index n = static_cast<Eigen::Index>(nx) * ny;
  if (rest_positions.cols() != n || inv_mass.size() != n) {
    throw std::invalid_argument("build_cloth_hierarchy: a " + std::to_string(nx) + " x " + std::to_string(ny) +
                                " grid needs " + std::to_string(n) + " rest positions and inverse masses (got " +
                                std::to_string(rest_positions.cols()) + " and " + std::to_string(inv_mass.size()) +
                                ")");
  }
  for (Eigen::Index p = 0; p < n; ++p) {
    if (!(inv_mass[p] >= 0.0) || !std::isfinite(inv_mass[p])) {
      throw std::invalid_argument("build_cloth_hierarchy: inv_mass[" + std::to_string(p) +
                                  "] must be finite and >= 0 (got " + std::to_string(inv_mass[p]) + ")");
    }
  }
  const int most = max_levels(nx, ny);
  if (levels < 1 || levels > most) {
    throw std::invalid_argument("build_cloth_hierarchy: levels must be in [1, " + std::to_string(most) +
                                "] for a " + std::to_string(nx) + " x " + std::to_string(ny) + " grid (got " +
                                std::to_string(levels) + ")");
  }

  ClothHierarchy hierarchy;
  HierarchyLevel finest;
  finest.nx = nx;
  finest.ny = ny;
  for (int col = 0; col < nx; ++col) finest.columns.push_back(col);
  for (int row = 0; row < ny; ++row) finest.rows.push_back(row);
  for (int p = 0; p < nx * ny; ++p) finest.particles.push_back(p);
  finest.inv_mass = inv_mass;
  finest.springs = springs;
  hierarchy.levels.push_back(std::move(finest));

  for (int l = 1; l < levels; ++l) {
    HierarchyLevel& fine = hierarchy.levels.back();
    const std::vector<int> keep_columns = coarser_lines(fine.nx);
    const std::vector<int> keep_rows = coarser_lines(fine.ny);
    HierarchyLevel coarse;
    coarse.columns = pick(fine.columns, keep_columns);
    coarse.rows = pick(fine.rows, keep_rows);
    coarse.nx = static_cast<int>(coarse.columns.size());
    coarse.ny = static_cast<int>(coarse.rows.size());
    auto id = [nx](int row, int col) { return row * nx + col; };
    for (const int row : coarse.rows) {
      for (const int col : coarse.columns) coarse.particles.push_back(id(row, col));
    }

    // Masses: a coarse particle keeps its own and collects its share of every
    // movable finer particle it parents. Pinned particles (infinite mass) stay pinned.
    Eigen::VectorXd mass = Eigen::VectorXd::Zero(n);
    for (const int p : coarse.particles) mass[p] = fine.inv_mass[p] > 0.0 ? 1.0 / fine.inv_mass[p] : 0.0;
    for (int a = 0; a < fine.ny; ++a) {
      const LineParents down = line_parents(fine.rows[static_cast<std::size_t>(a)], coarse.rows);
      for (int b = 0; b < fine.nx; ++b) {
        const LineParents across = line_parents(fine.columns[static_cast<std::size_t>(b)], coarse.columns);
        if (down.count == 1 && across.count == 1) continue;  // on the coarse level itself
        Interpolation entry;
        entry.particle = id(fine.rows[static_cast<std::size_t>(a)], fine.columns[static_cast<std::size_t>(b)]);
        for (int r = 0; r < down.count; ++r) {
          for (int c = 0; c < across.count; ++c) {
            entry.parents.push_back(id(coarse.rows[static_cast<std::size_t>(down.index[r])],
                                       coarse.columns[static_cast<std::size_t>(across.index[c])]));
            entry.weights.push_back(down.weight[r] * across.weight[c]);
          }
        }
        const double w = fine.inv_mass[entry.particle];
        if (w > 0.0) {
          for (std::size_t k = 0; k < entry.parents.size(); ++k) {
            mass[entry.parents[k]] += entry.weights[k] / w;
          }
        }
        fine.prolongation.push_back(std::move(entry));
      }
    }
    coarse.inv_mass = Eigen::VectorXd::Zero(n);
    for (const int p : coarse.particles) {
      if (fine.inv_mass[p] > 0.0) coarse.inv_mass[p] = 1.0 / mass[p];
    }

    // Structural and shear constraints of the coarse grid, in the generator's order.
    for (int a = 0; a < coarse.ny; ++a) {
      for (int b = 0; b < coarse.nx; ++b) {
        const int here = coarse.particles[static_cast<std::size_t>(a * coarse.nx + b)];
        const bool right = b + 1 < coarse.nx, down = a + 1 < coarse.ny;
        const int next_col = right ? coarse.particles[static_cast<std::size_t>(a * coarse.nx + b + 1)] : -1;
        const int next_row = down ? coarse.particles[static_cast<std::size_t>((a + 1) * coarse.nx + b)] : -1;
        if (right) add_coarse_spring(coarse, rest_positions, here, next_col);
        if (down) add_coarse_spring(coarse, rest_positions, here, next_row);
        if (right && down) {
          const int diagonal = coarse.particles[static_cast<std::size_t>((a + 1) * coarse.nx + b + 1)];
          add_coarse_spring(coarse, rest_positions, here, diagonal);
          add_coarse_spring(coarse, rest_positions, next_col, next_row);
        }
      }
    }
    hierarchy.levels.push_back(std::move(coarse));
  }
  return hierarchy;
}

}  // namespace cl
