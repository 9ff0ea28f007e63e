// Occlusion sweeping on one block of a distributed volume (each MPI rank holds one block).
// The sweeps are global; a block sweeps its own voxels with a one-voxel ghost layer of D
// and of the octant visibilities V_s that hold its neighbours' values, frozen during a
// round. Between rounds the driver moves plain float buffers between face neighbours:
//
//   BlockSweeper block(scalars, placement, spacing, parameters);
//   block.initialise();
//   if (!(any rank's block.surfaceFound()))          // a max/or over the ranks
//     block.fillWithoutSurface();                     // as the serial code does
//   else
//     do {
//       block.runRound(parameters.iterations);
//       for each face f with faceValueCount(f) > 0: exportFace(f, out[f]), send out[f]
//       to the neighbour across f, receive in[f] from it (it exported oppositeFace(f))
//       change = max over f of block.importFace(f, in[f]);
//     } while (max over the ranks of change > tolerance);
//   block.finish(output);
//
// At the fixed point each block's sweeps compute the same Godunov updates and Eq. 6
// recursions as the serial sweeps of the whole volume, so the results agree with a
// converged serial run (iterations large, tolerance > 0) to about the tolerance. V crosses
// one block per round, so the rounds are about the blocks along the longest upwind chain
// plus one or two. Definitions: docs/methods.md, Singh et al.
#pragma once

#include "vao/OcclusionSweeping.h"

#include <array>
#include <cstdint>
#include <memory>

namespace vao
{

/// Faces of a block: 0 = -x, 1 = +x, 2 = -y, 3 = +y, 4 = -z, 5 = +z.
constexpr int kBlockFaces = 6;
inline int oppositeFace(int face)
{
  return face ^ 1;
}

/// Where a block lies in the whole volume. The blocks of a volume must form a grid (as
/// ParaView's extent translator splits it): a face neighbour shares the whole face.
struct BlockPlacement
{
  Index3 whole = { 0, 0, 0 }; // dimensions of the whole volume
  Index3 begin = { 0, 0, 0 }; // first own voxel, in the whole volume
  Index3 size = { 0, 0, 0 };  // own voxels per axis

  /// A neighbouring block exists across the face (it is not the whole volume's border).
  bool hasNeighbour(int face) const
  {
    const int axis = face / 2;
    return (face & 1) ? this->begin[axis] + this->size[axis] < this->whole[axis]
                      : this->begin[axis] > 0;
  }
  /// Dimensions of the scalars the block needs: its own voxels plus one ghost layer on
  /// every face that has a neighbour.
  Index3 scalarDims() const
  {
    Index3 d = this->size;
    for (int face = 0; face < kBlockFaces; ++face)
      d[face / 2] += this->hasNeighbour(face) ? 1 : 0;
    return d;
  }
};

/// Allocation failure never throws: initialise(), runRound() and finish() return a
/// Status that says memory (the constructor's own state included), and the other calls do
/// nothing until an initialise() has succeeded.
class BlockSweeper
{
public:
  /// scalars: dims == placement.scalarDims() (the own voxels with the neighbours' ghost
  /// layer of scalars, so that the iso crossings at a face are found as in serial). The
  /// view and the other arguments must stay valid until finish(). execution.threads and
  /// abortRequested apply to every call; progress is reported per call.
  BlockSweeper(const VolumeView& scalars, const BlockPlacement& placement,
    const std::array<double, 3>& spacing, const SweepParameters& parameters,
    const Execution& execution = {});
  ~BlockSweeper();
  BlockSweeper(const BlockSweeper&) = delete;
  BlockSweeper& operator=(const BlockSweeper&) = delete;

  /// Checks the arguments (as computeOcclusionSweeping, plus the placement), computes the
  /// initial D of the own voxels and sets the ghost layer to the open sky (D = +inf, V = 1).
  Status initialise();

  /// Some edge of the own voxels (to the scalar ghost layer included) crosses the iso
  /// value. When no block has one, call fillWithoutSurface() instead of the rounds.
  bool surfaceFound() const;

  /// The whole volume has no surface: D = +-(the whole volume's diagonal), V = 1 (all
  /// outside) or 0 (all inside), as computeOcclusionSweeping does.
  void fillWithoutSurface();

  /// Up to maxPasses passes of the 8 sweeps over the own voxels with the current ghost
  /// layer; stops after a pass that changes no finite |D| by parameters.tolerance (with a
  /// tolerance > 0). report: passes and lastChange of this round.
  Status runRound(int maxPasses, SweepReport* report = nullptr);

  /// Floats exchanged across the face: 5 per face voxel (D and V_s of the four octants
  /// whose sweeps cross the face in the direction of the neighbour); 0 without neighbour.
  std::int64_t faceValueCount(int face) const;

  /// Writes the own voxels' layer at the face, for the neighbour across it.
  void exportFace(int face, float* buffer) const;

  /// Sets the ghost layer at the face from what the neighbour across it exported (its
  /// oppositeFace). Returns the largest change of a ghost value (D in world units, V);
  /// infinity where a D becomes finite. 0 for a face without neighbour.
  double importFace(int face, const float* buffer);

  /// Writes D, AmbientOcclusion and OctantVisibility of the own voxels (x fastest over
  /// placement.size). N of the geometry term reads the ghost D at faces, so it is the
  /// serial central difference there.
  Status finish(const SweepOutput& output);

private:
  /// initialise() succeeded (the state exists and its buffers are made).
  bool initialised() const;

  struct State;
  std::unique_ptr<State> Impl; // null when even the state could not be allocated
};

} // namespace vao
