// Fonts, display check and PNG capture shared by the 3D view and the charts.
#include "navview_internal.h"

#include <cstdio>
#include <cstdlib>
#include <sys/stat.h>
#include <time.h>

#include <X11/Xlib.h>

#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

namespace {
bool Readable(const char *path) {
  struct stat st;
  return path && *path && stat(path, &st) == 0 && S_ISREG(st.st_mode);
}
} // namespace

std::string NavFontFile() {
  const char *env = std::getenv("NAVVIEW_FONT_FILE");
  if (Readable(env)) return env;
  if (Readable(NAVVIEW_DEFAULT_FONT_FILE)) return NAVVIEW_DEFAULT_FONT_FILE;
  return {};
}

void NavApplyFont(vtkTextProperty *tprop) {
  static const std::string font = NavFontFile();
  static bool warned = false;
  if (font.empty()) {
    if (!warned) {
      std::fprintf(stderr,
                   "navview: warning: font %s not found (install fonts-dejavu-core or set "
                   "NAVVIEW_FONT_FILE); brackets and Greek letters will not render\n",
                   NAVVIEW_DEFAULT_FONT_FILE);
      warned = true;
    }
    return;
  }
  tprop->SetFontFamily(VTK_FONT_FILE);
  tprop->SetFontFile(font.c_str());
}

// One X connection for the whole process, opened with retries and handed to every VTK window
// (NavAttachDisplay). Under heavy load a fresh XOpenDisplay on the shared Xvfb sometimes failed
// ("bad X server connection", then VTK aborts): 5 of 15 chart renders at load average 14.
// Retrying here, once, and never opening another connection removes that failure mode.
static Display *g_display = nullptr;

bool NavCheckDisplay(std::string *error) {
  if (g_display) return true;
  const char *name = std::getenv("DISPLAY");
  if (!name || !*name) {
    *error = "no X display (DISPLAY is not set); VTK 9.1 on Debian renders only through X, also "
             "offscreen: run under xvfb-run -a";
    return false;
  }
  for (int attempt = 0; attempt < 40 && !g_display; ++attempt) {
    g_display = XOpenDisplay(name);
    if (!g_display) {
      struct timespec ts = {0, 150000000L}; // 150 ms, 6 s in all
      nanosleep(&ts, nullptr);
    }
  }
  if (!g_display) {
    *error = std::string("cannot open X display '") + name + "'; run under xvfb-run -a";
    return false;
  }
  return true;
}

void NavAttachDisplay(vtkRenderWindow *window) {
  if (g_display) window->SetDisplayId(g_display);
}

bool NavWriteWindowPng(vtkRenderWindow *window, const std::string &path, std::string *error) {
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(path.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0) {
    *error = path + ": error: cannot write the PNG";
    return false;
  }
  return true;
}
