/**
 * @file nav_export.h
 * @brief Symbol visibility and attribute macros shared by every navcore header.
 */
#ifndef NAV_EXPORT_H
#define NAV_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define NAV_API __attribute__((visibility("default")))
#define NAV_NODISCARD __attribute__((warn_unused_result))
#define NAV_DEPRECATED __attribute__((deprecated))
#else
#define NAV_API
#define NAV_NODISCARD
#define NAV_DEPRECATED
#endif

#ifdef __cplusplus
#define NAV_BEGIN_DECLS extern "C" {
#define NAV_END_DECLS }
#else
#define NAV_BEGIN_DECLS
#define NAV_END_DECLS
#endif

#endif /* NAV_EXPORT_H */
