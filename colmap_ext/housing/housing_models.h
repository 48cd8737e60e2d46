// The list of housing (port) models and runtime look-ups over it.
#pragma once

#include <string>

#include "colmap_ext/housing/dome_port.h"
#include "colmap_ext/housing/flat_port.h"
#include "colmap_ext/util/error.h"
#include "colmap_ext/util/type_list.h"

namespace portcal {

using HousingModelList = TypeList<FlatPort, DomePort>;

// The models' names, ", "-separated in the list's order ("FLATPORT,
// DOMEPORT"), and with their ids ("FLATPORT = 0, DOMEPORT = 1"): what
// messages list, so a new model appears in them.
std::string HousingModelNames();
std::string HousingModelIds();

template <typename F>
void VisitHousingModel(int model_id, F&& f) {
  if (!VisitModelById(HousingModelList{}, model_id, std::forward<F>(f))) {
    throw InputError("unknown housing model id " + std::to_string(model_id) + " (" +
                     HousingModelIds() + ")");
  }
}

bool ExistsHousingModelWithName(const std::string& name);
// Throws InputError listing the valid names.
int HousingModelNameToId(const std::string& name);
std::string HousingModelIdToName(int model_id);
int HousingModelNumParams(int model_id);
std::string HousingModelParamsInfo(int model_id);

}  // namespace portcal
