// The CUDA backend: the passes of Pipeline.h as GPU kernels, one thread per index, plus
// transfers, a tiled transpose and error handling. The maths and the indexing live in
// Pipeline.h (shared with the host emulation that tests them without a GPU) and
// Estimators.h (shared with the CPU path).
#include "vao/Cuda.h"
#include "vao/Validation.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"
#include "cpu/exact_reference/ExactReference.h"
#include "cpu/moment_pyramid/PyramidPlan.h"
#include "cuda/CudaExecutor.h"
#include "cuda/common/Pipeline.h"
#include "cuda/common/SlabTransfers.h"
#include "cuda/exact_reference/ExactPipeline.h"
#include "cuda/histogram_cdf/HistogramPipeline.h"
#include "cuda/moment_pyramid/PyramidPipeline.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace vao
{
namespace cuda
{
namespace
{

using gpu::Index;

std::atomic<int> injectedFailures{ 0 };

/// Throws the failure a test asked for (injectDeviceFailures), once per call.
void failIfInjected()
{
  int left = injectedFailures.load();
  while (left > 0 && !injectedFailures.compare_exchange_weak(left, left - 1))
  {
  }
  if (left > 0)
  {
    throw CudaFailure("CUDA injected failure (injectDeviceFailures, for tests)");
  }
}

/// Host pointers of the results (null: not asked for), region-sized.
struct HostOutputs
{
  float* openness = nullptr;
  float* variance = nullptr;
  BoxStatisticsOutput statistics;
  // Histogram CDF's or an exact reference's openness instead (counts, not moments).
  const AmbientOcclusionParameters* counting = nullptr;
};

/// The openness of Histogram CDF (HistogramPipeline.h) or of an exact reference
/// (ExactPipeline.h) into hostOpenness.
template <class T>
void runCounting(const VolumeView& view, const Region& region, const AmbientOcclusionParameters& p,
  float* hostOpenness, const Execution& execution, Timing* timing)
{
  const detail::TypedVolume<T> volume(view);
  const gpu::RegionGeometry g = gpu::geometryFor(view.dims, region, p.radius);
  CudaExecutor ex(timing, execution);
  DeviceBuffer<T> input(g.block());
  uploadBlock(volume, region, g, input.get(), execution.threads);
  failIfInjected();
  ex.progress(0.1);
  DeviceBuffer<float> openness(g.region());
  const bool iso = p.queryMode == QueryMode::IsoValue;
  if (p.method == Method::HistogramCdf)
  {
    gpu::runHistogramPasses<T>(ex, input.get(), g, p.thresholds.data(),
      static_cast<int>(p.thresholds.size()), iso, p.isoValue, openness.get());
  }
  else
  {
    gpu::runExactPasses<T>(ex, input.get(), g,
      detail::neighbourhoodRowHalfWidths(p.radius, p.method == Method::ExactSphere), iso,
      p.isoValue, openness.get(), 0.1, 0.95);
  }
  if (timing)
  {
    ex.finish();
  }
  ex.download(hostOpenness, openness.get(), g.region());
  ex.progress(1.0);
}

template <class T>
void run(const VolumeView& view, const Region& region, const Radius& radius, bool withExtrema,
  gpu::EstimatorSetting estimator, const ValueScan& scan, const HostOutputs& host,
  const Execution& execution, Timing* timing)
{
  using Acc = typename detail::MomentTraits<T>::Accumulator;
  const detail::TypedVolume<T> volume(view);
  const gpu::RegionGeometry g = gpu::geometryFor(view.dims, region, radius);
  const detail::MomentScale scale =
    detail::momentScale(volume, scan.minimum, scan.maximum, estimator.basis);
  const Acc shift = static_cast<Acc>(scale.shift);
  estimator.roundingVariance = scale.roundingVariance;
  const BoxStatisticsOutput& st = host.statistics;
  if (gpu::fusedPassFits<Acc, T>(g, withExtrema, sharedMemoryLimit()))
  {
    // One kernel, z slabs streamed: SlabTransfers.h.
    const auto bytes = [](auto* p) { return reinterpret_cast<unsigned char*>(p); };
    const OutputArray outputs[kFusedOutputs] = { { bytes(host.openness), 4 },
      { bytes(host.variance), 4 }, { bytes(st.count), 8 }, { bytes(st.mean), 8 },
      { bytes(st.variance), 8 }, { bytes(st.minimum), 8 }, { bytes(st.maximum), 8 } };
    runFusedSlabs<T, Acc>(
      volume, region, g, shift, estimator, withExtrema, outputs, execution, timing, failIfInjected);
    return;
  }
  CudaExecutor ex(timing, execution);
  DeviceBuffer<T> input(g.block());
  uploadBlock(volume, region, g, input.get(), execution.threads);
  failIfInjected();
  ex.progress(0.1);

  const Index n = g.region();
  DeviceBuffer<float> openness(host.openness ? n : 0), variance(host.variance ? n : 0);
  DeviceBuffer<double> count(st.count ? n : 0), mean(st.mean ? n : 0),
    varianceD(st.variance ? n : 0), minimum(st.minimum ? n : 0), maximum(st.maximum ? n : 0);
  const gpu::FinalOutputs out{ openness.get(), variance.get(), count.get(), mean.get(),
    varianceD.get(), minimum.get(), maximum.get() };
  gpu::runPasses<T, Acc>(ex, input.get(), g, withExtrema, shift, estimator, out);
  if (timing)
  {
    ex.finish();
  }

  auto download = [&](auto* to, const auto& from)
  {
    if (to)
      ex.download(to, from.get(), n);
  };
  download(host.openness, openness);
  download(host.variance, variance);
  download(st.count, count);
  download(st.mean, mean);
  download(st.variance, varianceD);
  download(st.minimum, minimum);
  download(st.maximum, maximum);
  ex.progress(1.0);
}

/// Runs work() on the device that execution.device selects: the device errors, Abort and
/// a host allocation failure come back as a Status; the wall-clock total goes to timing.
template <class Work>
Status onDevice(const Execution& execution, Timing* timing, const Work& work)
{
  const DeviceStatus device = deviceStatus(execution.device);
  if (!device.available)
  {
    return Status::device("no CUDA device: " + device.description);
  }
  const auto start = std::chrono::steady_clock::now();
  if (timing)
  {
    *timing = Timing{};
  }
  try
  {
    check(cudaSetDevice(device.index), "device selection");
    work();
    check(cudaDeviceSynchronize(), "synchronize");
  }
  catch (const CudaFailure& failure)
  {
    cudaGetLastError(); // clear a non-sticky error so the next call starts clean
    return Status::device(failure.what());
  }
  catch (const Cancelled&)
  {
    cudaGetLastError();
    return Status::cancelled();
  }
  catch (const std::bad_alloc&)
  {
    return Status::device("out of host memory for the transfer");
  }
  if (timing)
  {
    timing->totalMilliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return Status::success();
}

Status runChecked(const VolumeView& view, const Region& region, const Radius& radius,
  bool withExtrema, const gpu::EstimatorSetting& estimator, const HostOutputs& host,
  const Execution& execution, Timing* timing)
{
  ValueScan scan;
  Status status;
  if (host.counting)
  {
    // Counts, not moments: no magnitude limit, only finite values.
    status = validate(view, region, radius);
    if (status.ok && needsValueScan(view.type))
      status = finiteStatus(scanValues(view));
  }
  else
  {
    status = validateMomentRequest(view, region, radius, scan);
  }
  if (!status.ok)
  {
    return status;
  }
  return onDevice(execution, timing,
    [&]
    {
      detail::dispatchScalarType(view.type,
        [&](auto tag)
        {
          if (host.counting)
            runCounting<decltype(tag)>(
              view, region, *host.counting, host.openness, execution, timing);
          else
            run<decltype(tag)>(
              view, region, radius, withExtrema, estimator, scan, host, execution, timing);
        });
    });
}

} // namespace

bool built()
{
  return true;
}

DeviceStatus deviceStatus(int requested)
{
  // The visible devices, queried once: how many, and each one's description.
  static std::once_flag once;
  static std::vector<std::string> devices;
  static std::string none;
  std::call_once(once,
    []
    {
      int count = 0;
      const cudaError_t error = cudaGetDeviceCount(&count);
      if (error != cudaSuccess || count == 0)
      {
        none = std::string("no usable CUDA device (") +
          (error != cudaSuccess ? cudaGetErrorString(error) : "none found") + ")";
        cudaGetLastError();
        return;
      }
      for (int i = 0; i < count; ++i)
      {
        cudaDeviceProp properties;
        std::ostringstream text;
        if (cudaGetDeviceProperties(&properties, i) == cudaSuccess)
          text << properties.name << " (" << properties.totalGlobalMem / (1024 * 1024)
               << " MiB, sm_" << properties.major << properties.minor << ")";
        else
          text << "(cannot be queried)";
        devices.push_back(text.str());
      }
    });
  DeviceStatus status;
  const int count = static_cast<int>(devices.size());
  status.index = chooseDevice(requested, count, detail::nodeLocalRank());
  if (status.index < 0)
  {
    std::ostringstream why;
    if (count == 0)
      why << none;
    else
      why << "CUDA device " << requested << " requested, but " << count
          << " visible (CUDA_VISIBLE_DEVICES counts)";
    status.description = why.str();
    return status;
  }
  std::ostringstream text;
  text << "device " << status.index << " of " << count << ": "
       << devices[static_cast<std::size_t>(status.index)];
  status.available = true;
  status.description = text.str();
  return status;
}

Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& p, const AmbientOcclusionOutput& output,
  const Execution& execution, Timing* timing)
{
  if (p.queryMode == QueryMode::SmoothedValue)
  {
    return Status::device("the smoothed query runs on the CPU only");
  }
  if (p.method == Method::TransferFunction)
  {
    return Status::device("the Transfer Function method runs on the CPU only");
  }
  if (!isSeparableMethod(p.method))
  {
    Status status =
      p.method == Method::HistogramCdf ? checkHistogramThresholds(p.thresholds) : Status::success();
    if (status.ok && p.method != Method::HistogramCdf && p.method != Method::ExactBox &&
      p.method != Method::ExactSphere)
      status = Status::failure("unknown method");
    if (status.ok && p.queryMode == QueryMode::IsoValue)
      status = checkFiniteParameter(p.isoValue, "the iso value");
    HostOutputs host;
    host.openness = output.openness;
    host.counting = &p;
    gpu::EstimatorSetting none{ Method::GaussianCdf, QueryMode::VoxelValue, 0.0, ErfMode::Exact };
    none.basis = p.momentBasis;
    if (status.ok && output.openness)
      status = runChecked(volume, region, p.radius, false, none, host, execution, timing);
    if (status.ok && output.variance)
    {
      HostOutputs variance; // the box variance comes from the moments, as on the CPU
      variance.variance = output.variance;
      status = runChecked(volume, region, p.radius, false, none, variance, execution, timing);
    }
    return status;
  }
  if (p.queryMode == QueryMode::IsoValue)
  {
    const Status iso = checkFiniteParameter(p.isoValue, "the iso value");
    if (!iso.ok)
      return iso;
  }
  HostOutputs host;
  host.openness = output.openness;
  host.variance = output.variance;
  const bool withExtrema = output.openness && p.method == Method::CdfReconstruction;
  gpu::EstimatorSetting estimator{ p.method, p.queryMode, p.isoValue, p.erfMode };
  estimator.basis = p.momentBasis;
  return runChecked(volume, region, p.radius, withExtrema, estimator, host, execution, timing);
}

Status computeBoxStatistics(const VolumeView& volume, const Region& region, const Radius& radius,
  const BoxStatisticsOutput& output, const Execution& execution, Timing* timing)
{
  HostOutputs host;
  host.statistics = output;
  return runChecked(volume, region, radius, output.minimum || output.maximum,
    { Method::GaussianCdf, QueryMode::VoxelValue, 0.0, ErfMode::Exact }, host, execution, timing);
}

Status buildMomentPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution, Timing* timing)
{
  detail::PyramidSetup setup;
  Status status = detail::preparePyramid(volume, origin, spacing, parameters, setup);
  std::vector<MomentLevel> levels;
  if (status.ok)
  {
    status = onDevice(execution, timing,
      [&]
      {
        detail::dispatchScalarType(volume.type,
          [&](auto tag)
          {
            using T = decltype(tag);
            const Region whole = Region::whole(volume);
            const gpu::RegionGeometry g = gpu::geometryFor(volume.dims, whole, { 0, 0, 0 });
            CudaExecutor ex(timing, execution);
            DeviceBuffer<T> input(g.block());
            uploadBlock(detail::TypedVolume<T>(volume), whole, g, input.get(), execution.threads);
            failIfInjected();
            ex.progress(0.1);
            gpu::runPyramid<T>(ex, input.get(), volume.dims, setup, parameters.levels, levels);
            if (timing)
            {
              ex.finish();
            }
          });
      });
  }
  pyramid.clear();
  if (!status.ok)
  {
    return status;
  }
  detail::setLevelGeometry(levels, origin, spacing, setup);
  pyramid = std::move(levels);
  return status;
}

void injectDeviceFailures(int calls)
{
  injectedFailures.store(calls > 0 ? calls : 0);
}

double measureCopyBandwidth(double bytes)
{
  const DeviceStatus device = deviceStatus();
  if (!device.available || bytes <= 0)
  {
    return 0.0;
  }
  try
  {
    check(cudaSetDevice(device.index), "device selection");
    const Index n = static_cast<Index>(bytes);
    DeviceBuffer<char> from(n), to(n);
    check(cudaMemcpy(to.get(), from.get(), n, cudaMemcpyDeviceToDevice), "copy"); // warm-up
    cudaEvent_t start, stop;
    check(cudaEventCreate(&start), "event");
    check(cudaEventCreate(&stop), "event");
    float best = 1e30f;
    for (int repeat = 0; repeat < 5; ++repeat)
    {
      check(cudaEventRecord(start), "event record");
      check(cudaMemcpy(to.get(), from.get(), n, cudaMemcpyDeviceToDevice), "copy");
      check(cudaEventRecord(stop), "event record");
      check(cudaEventSynchronize(stop), "copy");
      float ms = 0.0f;
      check(cudaEventElapsedTime(&ms, start, stop), "event time");
      best = std::min(best, ms);
    }
    cudaEventDestroy(start);
    cudaEventDestroy(stop);
    return 2.0 * bytes / (best * 1e-3) / 1e9; // read + write, like the passes' traffic
  }
  catch (const CudaFailure&)
  {
    cudaGetLastError();
    return 0.0;
  }
}

} // namespace cuda
} // namespace vao
