#include "render/offscreen_png.h"

#include <vtkErrorCode.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkWindowToImageFilter.h>

#include <X11/Xlib.h>

#include <cstdlib>
#include <stdexcept>
#include <system_error>

namespace liversim {

void check_offscreen_png_target(const std::filesystem::path& file, const std::string& action) {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0')
    throw std::runtime_error("cannot " + action + " " + file.string() +
                             ": no X display (DISPLAY is unset); run the command inside "
                             "xvfb-run -a");
  const std::filesystem::path folder =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(folder))
    throw std::runtime_error("cannot write " + file.string() + ": folder " + folder.string() +
                             " does not exist");
}

void use_shared_x_connection(vtkRenderWindow* window) {
  // Never closed: it lives as long as the process, so the server always has this client.
  static Display* const connection = XOpenDisplay(nullptr);
  // Without one (no server), the window tries its own and VTK reports the failure.
  if (connection != nullptr && window->GetGenericDisplayId() == nullptr)
    window->SetDisplayId(connection);
}

void write_window_png(vtkRenderWindow* window, const std::filesystem::path& file) {
  use_shared_x_connection(window);
  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(file.string().c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0) {
    std::error_code ignored;
    std::filesystem::remove(file, ignored);
    throw std::runtime_error("writing " + file.string() + " failed (" +
                             vtkErrorCode::GetStringFromErrorCode(writer->GetErrorCode()) + ")");
  }
}

}  // namespace liversim
