/**
 * @file navview_internal.h
 * @brief Helpers shared by the libnavview sources; private (VTK types allowed), never installed.
 */
#ifndef NAVVIEW_INTERNAL_H
#define NAVVIEW_INTERNAL_H

#include <string>

class vtkRenderWindow;
class vtkTextProperty;

/** The TrueType font for every label: $NAVVIEW_FONT_FILE, else the build's default (DejaVu
 *  Sans from fonts-dejavu-core). Empty when neither file exists. */
std::string NavFontFile();

/** Use NavFontFile() on @p tprop (VTK_FONT_FILE); without it VTK's built-in font draws [ ] as
 *  ( ) and has no Greek, so a warning is printed once and the built-in font stays. */
void NavApplyFont(vtkTextProperty *tprop);

/** Whether an X display can be opened. VTK 9.1 on Debian has no EGL/OSMesa: even offscreen
 *  rendering needs X, and without it vtkXOpenGLRenderWindow aborts the process. Checked first so
 *  that the viewer fails with a message instead. */
bool NavCheckDisplay(std::string *error);

/** Give @p window the process's X connection (opened by NavCheckDisplay, which must have
 *  succeeded first), so that VTK opens no connection of its own. */
void NavAttachDisplay(vtkRenderWindow *window);

/** Read the back buffer of @p window and write it as an RGB PNG. */
bool NavWriteWindowPng(vtkRenderWindow *window, const std::string &path, std::string *error);

#endif /* NAVVIEW_INTERNAL_H */
