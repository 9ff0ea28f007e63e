// Private helpers of the module's filters: the collective operations of their distributed
// paths (agreement on a failure, global ranges, moving pieces of images and of a pyramid
// level between processes). Every function here is collective: each process of the
// controller must call it, in the same order. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionCollectives_h
#define vtkAmbientOcclusionCollectives_h

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
/// `held` (its block, any extent) and wants `wanted` (its requested extent, possibly
/// empty); each receives the parts of the others' blocks that overlap what it wants.
/// `output` gets the wanted extent with held's geometry and point arrays.
void RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output);

/// A pyramid level held in pieces, made whole on every process: each passes its piece
/// (`part`: float arrays "Mean" and "Variance", its extent in the whole level's grid;
/// null or empty for none) and receives the mean and variance of the whole level in
/// `level`, whose dims the caller sets. Where pieces overlap they hold the same values.
void GatherLevel(
  vtkMultiProcessController* controller, vtkImageData* part, vao::MomentLevel& level);

} // namespace vtkAmbientOcclusionCollectives

#endif
