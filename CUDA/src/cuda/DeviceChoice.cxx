// The choice of a CUDA device, in every build (plain C++: the CUDA backend and its stub
// both use it).
#include "vao/Cuda.h"

namespace vao
{
namespace cuda
{

int chooseDevice(int requested, int count, int nodeLocalRank)
{
  if (count <= 0 || requested >= count)
  {
    return -1;
  }
  return requested >= 0 ? requested : (nodeLocalRank > 0 ? nodeLocalRank : 0) % count;
}

} // namespace cuda
} // namespace vao
