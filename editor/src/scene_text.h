/*
 * navstudio: saving a scene into the text the user wrote, so that comments, blank lines, key
 * order and flow/block style survive a save.
 *
 * The scene is always written by navcore's writer first (the canonical text). The canonical text
 * of the scene as it was loaded (old) and of the scene being saved (new) are compared node by
 * node; each difference is spliced into the user's original text at the place of that key or
 * list item (libfyaml's parser gives the byte positions): a changed value replaces the value's
 * text (a changed flow item such as "- {kind: hold, duration_s: 20}" is rewritten as a whole,
 * with any comment inside its braces), a key the user's file does not have is added to its
 * mapping (canonical spelling), a removed key loses its lines; the items of a block list whose
 * length changed are aligned (longest common subsequence), so unchanged items and the comments
 * between them stay, removed items lose their lines and new items get lines of their own. What
 * cannot be placed (a flow collection that changes length, a key the user spelled in another
 * unit) is replaced whole. The caller checks the result: it must read back to exactly the scene
 * being saved, else the coarser levels follow (replace whole top-level sections, then the
 * canonical text).
 * No widget code; GUI thread (or any single thread).
 */
#ifndef NAVSTUDIO_SCENE_TEXT_H
#define NAVSTUDIO_SCENE_TEXT_H

#include <QByteArray>
#include <QString>
#include <QStringList>

namespace studio {

/** How much of the user's text a merge keeps. */
enum class MergeLevel {
  Fine,     /**< only the changed values / keys / lists are rewritten */
  Sections, /**< every top-level section with a change is rewritten whole */
};

/**
 * Splice the differences between @p canon_old and @p canon_new (both texts of navcore's writer)
 * into @p user (the text the scene was loaded from, which read gives the scene of @p canon_old).
 * @param[out] replaced  the scene-file paths whose text was replaced whole (their inner comments
 *                       are lost), comma-separated; empty when only values changed.
 * @return the merged text; empty on failure (a text libfyaml cannot parse, a block scalar...).
 */
QByteArray MergeSceneText(const QByteArray &user, const QByteArray &canon_old, const QByteArray &canon_new,
                          MergeLevel level, QString *replaced);

/** The scalar at @p keys (a path of mapping keys) of the YAML @p text; false when absent. */
bool SceneScalar(const QByteArray &text, const QStringList &keys, QByteArray *value);

} // namespace studio

#endif
