// The session file (`session-save`, `session-load`): the volume, transfer function, view, tools and
// overlays as JSON.
#include <filesystem>

#include "app/viewer_app.h"
#include "app/viewer_app_internal.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace vs::viewer {

nlohmann::json ViewerApp::sessionJson() const {
  VS_REQUIRE(hasVolume(), "session: no volume loaded");
  nlohmann::json j;
  j["volscissors_session"] = 1;
  j["volume"] = source_;
  if (!orientation_.empty()) j["orientation"] = orientation_;
  j["transfer_function"] = nlohmann::json::parse(tf_.toJson());
  j["view"] = {{"mode", renderModeName(view_.mode)},
               {"tf", view_.tf},
               {"azimuth_deg", view_.azimuthDeg},
               {"elevation_deg", view_.elevationDeg},
               {"zoom", view_.zoom},
               {"pan_mm", view_.panMm},
               {"window", view_.window.window},
               {"level", view_.window.level},
               {"cursor", view_.cursor},
               {"mono_axis", view_.monoAxis},
               {"stereo", stereoName(view_.stereo)},
               {"eye_separation", view_.eyeSeparation},
               {"convergence", view_.convergence},
               {"jitter", view_.jitter},
               {"shading", view_.shading},
               {"slice_zoom", view_.sliceZoom},
               {"slice_pan", view_.slicePan},
               {"slice_planes_3d", view_.slicePlanesIn3D}};
  if (view_.cutBox) j["view"]["cut_box"] = *view_.cutBox;  // absent: the cursor's box
  j["tool"] = toolName(tool_);
  j["snap"] = snap_;
  nlohmann::json clicks = nlohmann::json::array();
  for (const auto& c : liveWire_.clicks()) clicks.push_back({c[0], c[1]});
  j["livewire"] = {{"axis", liveWire_.axis()},
                   {"index", liveWire_.index()},
                   {"clicks", clicks},
                   {"closed", liveWire_.contour().closed},
                   {"cooling", liveWire_.cooling()}};
  nlohmann::json pts = nlohmann::json::array();
  for (const auto& p : trace_.points()) pts.push_back({p[0], p[1], p[2]});
  j["trace"] = {{"points", pts},
                {"auto_terminals", trace_.autoTerminals()},
                {"cost", trace_.costKind()},
                {"polarity", trace_.polarity() == TubePolarity::Dark ? "dark" : "bright"},
                {"has_result", trace_.hasResult()}};
  nlohmann::json corners = nlohmann::json::array(), via = nlohmann::json::array();
  for (const auto& c : surface_.cornerOverrides()) corners.push_back(c ? nlohmann::json(*c) : nlohmann::json());
  for (const auto& [side, sidePoints] : surface_.allVia()) via.push_back({side, sidePoints});
  j["surface"] = {{"level", surface_.level()},
                  {"closed", surface_.closed()},
                  {"planes", surface_.planes()},
                  {"has_result", surface_.hasResult()},
                  {"side", surface_.selectedSide()},
                  {"corners", corners},
                  {"via", via}};
  nlohmann::json cutPts = nlohmann::json::array();
  for (const Vec3& p : cut_.points()) cutPts.push_back({p.x(), p.y(), p.z()});
  j["cut"] = {
      {"points", cutPts}, {"iso", cut_.iso()}, {"iso_auto", cut_.isoAutomatic()}, {"has_result", cut_.hasResult()}};
  const CutWeights cw = cut_.weights();
  for (const CutWeightName& n : cutWeightNames()) j["cut"]["weights"][n.key] = cw.*n.field;
  nlohmann::json hidden = nlohmann::json::array();
  for (int l : overlays_.hiddenLabels) hidden.push_back(l);
  nlohmann::json overlayFiles = nlohmann::json::array();
  for (const LoadedOverlay& o : loadedOverlays_) overlayFiles.push_back(o.path);
  j["overlays"] = {{"files", overlayFiles},
                   {"labels", loadedLabelsPath_},
                   {"label_opacity", overlays_.labelOpacity},
                   {"overlay_opacity", overlays_.overlayOpacity},
                   {"hidden_labels", hidden}};
  return j;
}

void ViewerApp::saveSession(const std::string& path) const { writeFileAtomically(path, sessionJson().dump(1) + "\n"); }

void ViewerApp::loadSession(const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(readTextFile(path, "the session file"));
  } catch (const nlohmann::json::exception& e) {
    throw IoError("session " + path + ": not valid JSON (" + e.what() + ")");
  }
  try {
    if (!j.contains("volscissors_session")) throw IoError("session " + path + ": not a volscissors session file");
    std::string vol = j.at("volume").get<std::string>();
    if (vol.rfind(kPhantomSource, 0) != 0 && !std::filesystem::exists(vol)) {
      // A relative volume path is also tried next to the session file.
      const auto beside = std::filesystem::path(path).parent_path() / vol;
      if (std::filesystem::exists(beside)) vol = beside.string();
    }
    load(vol, j.value("orientation", std::string()));
    const auto& v = j.at("view");
    setMode(renderModeFromName(v.at("mode").get<std::string>()));
    if (v.at("tf").get<std::string>() == kEditedTf)
      setEditedTransferFunction(TransferFunction::fromJson(j.at("transfer_function").dump(), path));
    else
      setTransferFunction(v.at("tf").get<std::string>());
    setOrbit(v.at("azimuth_deg").get<double>(), v.at("elevation_deg").get<double>());
    setZoom(v.at("zoom").get<double>());
    const auto pan = v.value("pan_mm", std::array<double, 2>{0, 0});  // sessions before the pan have none
    setPan(pan[0], pan[1]);
    setWindow(v.at("window").get<double>(), v.at("level").get<double>());
    setCursor(v.at("cursor").get<Index3>());
    setMonoAxis(v.at("mono_axis").get<int>());
    setStereo(stereoFromName(v.at("stereo").get<std::string>()));
    setStereoParameters(v.at("eye_separation").get<double>(), v.at("convergence").get<double>());
    setJitter(v.at("jitter").get<bool>());
    setShading(v.at("shading").get<bool>());
    const auto zooms = v.at("slice_zoom").get<std::array<double, 3>>();
    setSlicePlanesIn3D(v.value("slice_planes_3d", true));  // older sessions have none
    setCutBox(v.contains("cut_box") ? std::optional(v.at("cut_box").get<std::array<double, 6>>()) : std::nullopt);
    const auto pans = v.at("slice_pan").get<std::array<std::array<double, 2>, 3>>();
    for (int a = 0; a < 3; ++a) setSliceView(a, zooms[size_t(a)], pans[size_t(a)]);
    // Points were stored after snapping: replay them without snapping.
    const auto& lw = j.at("livewire");
    liveWire_.setSlice(lw.at("axis").get<int>(), lw.at("index").get<int64_t>());
    liveWire_.setSnapRadius(0);
    liveWire_.setCooling(lw.value("cooling", 0));  // older sessions have none
    for (const auto& c : lw.at("clicks")) liveWire_.click({c.at(0).get<int64_t>(), c.at(1).get<int64_t>()});
    if (lw.at("closed").get<bool>()) liveWire_.close();
    const auto& tr = j.at("trace");
    for (const auto& p : tr.at("points")) trace_.click(p.get<Index3>());
    trace_.setAutoTerminals(tr.at("auto_terminals").get<int>());
    trace_.setCost(tr.at("cost").get<std::string>(),
                   tr.at("polarity").get<std::string>() == "dark" ? TubePolarity::Dark : TubePolarity::Bright);
    setSnap(j.at("snap").get<double>());
    tool_ = toolFromName(j.at("tool").get<std::string>());
    const auto& sf = j.at("surface");
    surface_.setLevel(sf.at("level").get<int>());
    surface_.setClosed(sf.at("closed").get<bool>());
    surface_.selectSide(sf.value("side", std::string("z+x+y")));  // older sessions have no edits
    surface_.clearCorners();
    if (sf.contains("corners"))
      for (int h = 0; h < 6; ++h)
        if (!sf.at("corners").at(size_t(h)).is_null())
          surface_.setCorner(h, sf.at("corners").at(size_t(h)).get<Index3>());
    if (sf.contains("via"))
      for (const auto& [side, pts] : sf.at("via").get<std::vector<std::pair<std::string, std::vector<Index3>>>>()) {
        surface_.selectSide(side);
        for (const Index3& p : pts) surface_.addVia(p);
      }
    surface_.selectSide(sf.value("side", std::string("z+x+y")));
    const ToolKind keep = tool_;
    const auto& ov = j.at("overlays");
    if (!ov.at("labels").get<std::string>().empty()) loadLabels(ov.at("labels").get<std::string>());
    setLabelOpacity(ov.at("label_opacity").get<double>());
    setOverlayOpacity(ov.at("overlay_opacity").get<double>());
    for (const auto& l : ov.at("hidden_labels")) setLabelVisible(l.get<int>(), false);
    for (const auto& f : ov.at("files")) addOverlay(f.get<std::string>());
    const auto& ct = j.at("cut");
    if (ct.at("iso_auto").get<bool>())
      setCutIso(std::nullopt);
    else
      setCutIso(ct.at("iso").get<double>());
    if (ct.contains("weights")) {  // sessions before issue 26 have none: the defaults
      CutWeights cw = defaultCutWeights();
      for (const CutWeightName& n : cutWeightNames()) cw.*n.field = ct.at("weights").at(n.key).get<double>();
      cut_.setWeights(cw);
    }
    for (const auto& p : ct.at("points"))
      cut_.click(Vec3(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>()));
    if (ct.at("has_result").get<bool>()) {
      tool_ = ToolKind::Cut;
      run(/*wait=*/true);
    }
    if (tr.at("has_result").get<bool>()) {
      tool_ = ToolKind::Trace;
      run(/*wait=*/true);
    }
    if (sf.at("has_result").get<bool>()) {
      // The mesh is recomputed at its planes; the cursor goes back to where the session had it.
      const Index3 cursor = view_.cursor;
      setCursor(sf.at("planes").get<Index3>());
      tool_ = ToolKind::Surface;
      run(/*wait=*/true);
      setCursor(cursor);
    }
    tool_ = keep;
  } catch (const nlohmann::json::exception& e) {
    throw IoError("session " + path + ": missing or ill-typed field (" + e.what() + ")");
  }
}

}  // namespace vs::viewer
