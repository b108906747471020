// What every tool of the viewer shares (without any core algorithm header, so the tools' own
// headers can include it whatever else they see).
#pragma once
#include <cstddef>
#include <string>

namespace vs::viewer {

constexpr size_t kUndoDepth = 100;  // per tool; the issue asks for >= 20

// What the viewer asks of the current tool without knowing which tool it is: undo, redo, the
// steps it can undo, saving its result, and which running job it must wait for. ViewerApp maps
// its ToolKind to the one Tool (ViewerApp::currentTool) and dispatches through this interface;
// the tools' own controls (clicks, parameters, runs) stay on their classes.
class Tool {
 public:
  // What a running background job keeps this tool from doing (undo, redo, save).
  enum class WaitFor {
    Nothing,      // edits are immediate (the live-wire)
    AnyJob,       // its own job (trace, surface) must end first
    Computation,  // any job but the cut contour's preparation (the cut)
  };
  virtual ~Tool() = default;
  virtual const char* name() const = 0;  // "livewire", "trace", "surface", "cut"
  virtual WaitFor waitFor() const = 0;
  // The job as the "still running" message names it ("the trace", "the extraction").
  virtual const char* jobName() const { return "the computation"; }
  virtual bool undo() = 0;
  virtual bool redo() = 0;
  virtual size_t undoSteps() const = 0;
  virtual void save(const std::string& path) const = 0;
};

// A file name the volume writers take (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd).
bool isVolumePath(const std::string& path);

}  // namespace vs::viewer
