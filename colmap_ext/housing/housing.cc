#include "colmap_ext/housing/housing.h"

#include "colmap_ext/camera/camera_models.h"
#include "colmap_ext/housing/housing_models.h"
#include "colmap_ext/housing/port_projection.h"

namespace portcal {

std::string HousingModelNames() { return ModelNames(HousingModelList{}); }

std::string HousingModelIds() {
  std::string ids;
  ForEachModel(HousingModelList{}, [&](auto model) {
    if (!ids.empty()) ids += ", ";
    ids += std::string(decltype(model)::kName) + " = " + std::to_string(decltype(model)::kId);
  });
  return ids;
}

bool ExistsHousingModelWithName(const std::string& name) {
  return VisitModelByName(HousingModelList{}, name, [](auto) {});
}

int HousingModelNameToId(const std::string& name) {
  int id = -1;
  if (!VisitModelByName(HousingModelList{}, name, [&](auto model) { id = decltype(model)::kId; })) {
    throw InputError("unknown housing model '" + name + "' (expected one of " +
                     HousingModelNames() + ")");
  }
  return id;
}

std::string HousingModelIdToName(int model_id) {
  std::string name;
  VisitHousingModel(model_id, [&](auto model) { name = decltype(model)::kName; });
  return name;
}

int HousingModelNumParams(int model_id) {
  int n = 0;
  VisitHousingModel(model_id, [&](auto model) { n = decltype(model)::kNumParams; });
  return n;
}

std::string HousingModelParamsInfo(int model_id) {
  std::string info;
  VisitHousingModel(model_id, [&](auto model) { info = decltype(model)::kParamsInfo; });
  return info;
}

Housing Housing::FromName(const std::string& model_name, std::vector<double> params,
                          const std::string& context) {
  Housing housing;
  try {
    housing.model_id = HousingModelNameToId(model_name);
  } catch (const InputError& e) {
    throw InputError(context + ": " + e.what());
  }
  housing.params = std::move(params);
  housing.Validate(context);
  return housing;
}

std::string Housing::ModelName() const { return HousingModelIdToName(model_id); }

std::string Housing::ParamsInfo() const { return HousingModelParamsInfo(model_id); }

void Housing::Validate(const std::string& context) const {
  std::optional<std::string> problem;
  bool known = VisitModelById(HousingModelList{}, model_id, [&](auto model) {
    using Port = decltype(model);
    if (static_cast<int>(params.size()) != Port::kNumParams) {
      problem = std::string(Port::kName) + " takes " + std::to_string(Port::kNumParams) +
                " parameters (" + Port::kParamsInfo + "), got " + std::to_string(params.size());
    } else {
      problem = Port::Invalidity(params.data());
    }
  });
  if (!known) {
    throw InputError(context + ": unknown housing model id " + std::to_string(model_id));
  }
  if (problem) throw InputError(context + ": " + *problem);
}

namespace {

// Calls f(Port) for the housing's model, its parameter count checked.
template <typename F>
void VisitPort(const Housing& housing, F&& f) {
  VisitHousingModel(housing.model_id, [&](auto model) {
    using Port = decltype(model);
    PORTCAL_CHECK(static_cast<int>(housing.params.size()) == Port::kNumParams);
    f(model);
  });
}

}  // namespace

void Housing::ValidateInput(const std::string& context) const {
  // Before Validate: a dome centre in millimetres fails its test of lying
  // inside the dome, and the units are the mistake to name.
  std::optional<std::string> mistake;
  VisitModelById(HousingModelList{}, model_id, [&](auto model) {
    using Port = decltype(model);
    if (static_cast<int>(params.size()) == Port::kNumParams)
      mistake = Port::UnitMistake(params.data());
  });
  if (mistake) throw InputError(context + ": " + *mistake);
  Validate(context);
}

std::optional<std::string> Housing::Implausibility() const {
  std::optional<std::string> why;
  VisitPort(*this, [&](auto model) { why = decltype(model)::Implausibility(params.data()); });
  return why;
}

std::string Housing::InWords() const {
  std::string words;
  VisitPort(*this, [&](auto model) { words = decltype(model)::InWords(params.data()); });
  return words;
}

HousingRefinement Housing::Refinement() const {
  HousingRefinement refinement;
  VisitPort(*this, [&](auto model) { refinement = decltype(model)::Refinement(params.data()); });
  return refinement;
}

bool Housing::AtBound() const {
  bool at_bound = false;
  VisitPort(*this, [&](auto model) { at_bound = decltype(model)::AtBound(params.data()); });
  return at_bound;
}

std::vector<Housing> Housing::StartCandidates(const Eigen::Vector3d& axis) const {
  std::vector<Housing> starts;
  VisitPort(*this, [&](auto model) {
    for (std::vector<double>& start : decltype(model)::StartCandidates(params.data(), axis)) {
      starts.push_back(Housing{model_id, std::move(start)});
    }
  });
  return starts;
}

double Housing::InAirFocalRatio() const {
  double ratio = 1;
  VisitPort(*this, [&](auto model) { ratio = decltype(model)::InAirFocalRatio(params.data()); });
  return ratio;
}

std::optional<Eigen::Vector2d> ProjectPoint(const Camera& camera, const Housing* housing,
                                            const Eigen::Vector3d& point_in_cam) {
  if (housing == nullptr) return camera.ImgFromCam(point_in_cam);
  std::optional<Eigen::Vector2d> pixel;
  VisitCameraModel(camera.model_id, [&](auto camera_model) {
    using CameraModel = decltype(camera_model);
    VisitHousingModel(housing->model_id, [&](auto port_model) {
      using Port = decltype(port_model);
      PORTCAL_CHECK(camera.params.size() == CameraModel::kNumParams);
      PORTCAL_CHECK(housing->params.size() == Port::kNumParams);
      Eigen::Vector2d xy;
      if (ImgFromWater<CameraModel, Port, double>(camera.params.data(), housing->params.data(),
                                                  point_in_cam, &xy.x(), &xy.y())) {
        pixel = xy;
      }
    });
  });
  return pixel;
}

std::optional<Ray3d> UnprojectPixel(const Camera& camera, const Housing* housing,
                                    const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Vector3d> dir = camera.CamFromImg(pixel);
  if (!dir) return std::nullopt;
  Ray3d ray;
  if (housing == nullptr) {
    ray.direction = dir->normalized();
    return ray;
  }
  bool ok = false;
  VisitHousingModel(housing->model_id, [&](auto port_model) {
    using Port = decltype(port_model);
    PORTCAL_CHECK(housing->params.size() == Port::kNumParams);
    ok = Port::RayInWater(housing->params.data(), *dir, &ray.origin, &ray.direction);
  });
  if (!ok) return std::nullopt;
  return ray;
}

}  // namespace portcal
