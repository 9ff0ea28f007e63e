// Private helpers of the module's filters: the collective operations of their distributed
// paths (agreement on a failure, global ranges, moving pieces of images and of a pyramid
// level between processes). Every function here is collective: each process of the
// controller must call it, in the same order. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionCollectives_h
#define vtkAmbientOcclusionCollectives_h

#include <string>
#include <vector>

class vtkImageData;
class vtkMultiProcessController;
namespace vao
{
struct MomentLevel;
}

namespace vtkAmbientOcclusionCollectives
{

/// The largest `value` over every process of the controller (a failure flag, a change).
double GlobalMax(vtkMultiProcessController* controller, double value);

/// range = [min, max] over every process of the controller (unchanged with one process
/// or none).
void GlobalRange(vtkMultiProcessController* controller, double range[2]);

/// Distributed data held as blocks to distributed data as requested: every process holds
/// `held` (its block, any extent; empty on the processes of a reader that does not split)
/// and wants `wanted` (an extent, possibly empty); each receives every voxel it wants
/// once, from itself where it can, else from the lowest process that holds it. `output`
/// gets the wanted extent with the holders' geometry and point arrays. False, with every
/// output empty, when some wanted voxel is held by no process (the same on every process).
bool RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output);

/// The image a process reads to compute its piece: `input` itself when every process's
/// input covers the extent it needs (`needed`, possibly empty), as readers that split
/// deliver it; else `fetched`, filled by RedistributeExtents from whatever the processes
/// hold (a reader that does not split reads everything on one process). Costs two
/// reductions when nothing is missing. nullptr, with `error` (the same on every process),
/// when the processes disagree on the data set's `whole` extent (each was handed its piece
/// as a whole volume: its AO would be wrong at the piece's borders), or when no process
/// holds some needed voxel.
vtkImageData* CoverNeededExtent(vtkMultiProcessController* controller, vtkImageData* input,
  const int whole[6], const int needed[6], vtkImageData* fetched, std::string& error);

/// One message of RedistributeExtents: the voxels `ext` from process `from` to `to`.
struct Transfer
{
  int from, to;
  int ext[6];
};

/// The messages that give each process r the extent wanted[6r..6r+5] from the blocks
/// held[6r..6r+5] (its own first, then the others' in rank order, each voxel once);
/// `complete` says whether every wanted voxel is held somewhere.
std::vector<Transfer> PlanTransfers(
  const std::vector<int>& held, const std::vector<int>& wanted, bool& complete);

/// A pyramid level held in pieces, made whole on every process: each passes its piece
/// (`part`: float arrays "Mean" and "Variance", its extent in the whole level's grid;
/// null or empty for none) and receives the mean and variance of the whole level in
/// `level`, whose dims the caller sets. Where pieces overlap they hold the same values.
void GatherLevel(
  vtkMultiProcessController* controller, vtkImageData* part, vao::MomentLevel& level);

} // namespace vtkAmbientOcclusionCollectives

#endif
