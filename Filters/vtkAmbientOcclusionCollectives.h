// Private helpers of the module's filters: the collective operations of their distributed
// paths (agreement on a failure, global ranges, moving pieces of images and of a pyramid
// level between processes). Every function here is collective: each process of the
// controller must call it, in the same order. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionCollectives_h
#define vtkAmbientOcclusionCollectives_h

#include "vtkType.h"

#include <string>
#include <vector>

class vtkImageData;
class vtkMultiProcessController;
namespace vao
{
struct MomentBasis;
struct MomentLevel;
struct VolumeView;
}

namespace vtkAmbientOcclusionCollectives
{

/// The bytes of voxel and pyramid data this process has sent to the others so far (pieces
/// and halos of RedistributeExtents, sweeping faces, pyramid levels): what the filters
/// report as AmbientOcclusionBytesSent. Reductions of a few values are not counted.
vtkIdType BytesSent();

/// Adds to BytesSent (for messages sent outside this file).
void CountSent(vtkIdType bytes);

/// Every process's list of items (`per` values each) in rank order, in `all`, with each
/// item's process in `owners`: the lists may differ in length. One process (or no
/// controller): its own list.
void GatherLists(vtkMultiProcessController* controller, const std::vector<double>& mine, int per,
  std::vector<double>& all, std::vector<int>& owners);

/// The largest `value` over every process of the controller (a failure flag, a change);
/// `value` itself with one process or no controller.
double GlobalMax(vtkMultiProcessController* controller, double value);

/// range = [min, max] over every process of the controller (unchanged with one process
/// or none).
void GlobalRange(vtkMultiProcessController* controller, double range[2]);

/// Distributed data held as blocks to distributed data as requested: every process holds
/// the images `held` (its blocks, any extents on one grid; none, or empty images, on the
/// processes of a reader that does not split) and wants the extents `wanted` (6 ints each,
/// possibly empty); `outputs[i]` receives every voxel of wanted extent i once, from the
/// process's own blocks where it can, else from the lowest process that holds it, with the
/// holders' geometry and point arrays. Only the voxels wanted elsewhere travel. False,
/// with every output empty, when some wanted voxel is held by no process (the same on
/// every process).
/// Without a controller (or with one process) nothing is sent.
bool RedistributeExtents(vtkMultiProcessController* controller,
  const std::vector<vtkImageData*>& held, const std::vector<int>& wanted,
  const std::vector<vtkImageData*>& outputs);

/// RedistributeExtents with one held block and one wanted extent on each process.
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

/// The moment basis of the whole data set (vao::MomentBasis) from its pieces: each process
/// passes the voxels it read (`volume`, extent `inputExt`; null when it holds none) and the
/// extent of its output piece; the pieces' voxels not in a lower process's piece are
/// sampled, so that overlapping pieces count once. Where the output pieces tile the whole
/// extent the basis is the one a run on the whole volume takes (to the rounding of the
/// sums). Collective.
vao::MomentBasis WholeMomentBasis(vtkMultiProcessController* controller,
  const vao::VolumeView* volume, const int inputExt[6], const int outExt[6], const int whole[6]);

/// One message of RedistributeExtents: the voxels `ext` of held block `block` from
/// process `from` to wanted extent `into` of process `to` (block and extent indices count
/// over every process).
struct Transfer
{
  int from, to, block, into;
  int ext[6];
};

/// The messages that give each wanted extent (wanted[6i..6i+5], on process
/// wantedOwners[i]) its voxels from the held blocks (held[6h..6h+5], on heldOwners[h]):
/// its own process's blocks first, then the others' in rank order, each voxel once.
/// `complete` says whether every wanted voxel is held somewhere.
std::vector<Transfer> PlanTransfers(const std::vector<int>& held,
  const std::vector<int>& heldOwners, const std::vector<int>& wanted,
  const std::vector<int>& wantedOwners, bool& complete);

/// A pyramid level held in pieces, made whole on every process: each passes its piece
/// (`part`: float arrays "Mean" and "Variance", its extent in the whole level's grid;
/// null or empty for none) and receives the mean and variance of the whole level in
/// `level`, whose dims the caller sets. Where pieces overlap they hold the same values.
void GatherLevel(
  vtkMultiProcessController* controller, vtkImageData* part, vao::MomentLevel& level);

} // namespace vtkAmbientOcclusionCollectives

#endif
