// The plugin's observers keep what they do per filter in small tables keyed by the
// filter proxy's XML name; this finds a proxy's entry.
#ifndef vtkAmbientOcclusionFilterTable_h
#define vtkAmbientOcclusionFilterTable_h

#include "vtkSMProxy.h"

#include <cstddef>
#include <cstring>

/// The entry of `table` whose `Filter` names the proxy, a filter of the "filters" group;
/// nullptr for any other proxy.
template <class Entry, std::size_t N>
const Entry* vtkAmbientOcclusionFilterEntry(const Entry (&table)[N], vtkSMProxy* proxy)
{
  if (!proxy || !proxy->GetXMLGroup() || std::strcmp(proxy->GetXMLGroup(), "filters") != 0)
  {
    return nullptr;
  }
  for (const Entry& entry : table)
  {
    if (std::strcmp(proxy->GetXMLName(), entry.Filter) == 0)
    {
      return &entry;
    }
  }
  return nullptr;
}

#endif
