/* What fmi2.h and fmi3.h share: the mark of the functions an FMU exports. A library built with
 * -fvisibility=hidden exports these only. Define QUADCOSIM_FMI_EXPORT before including either header
 * to mark them otherwise. Usable from C and C++. */
#ifndef QUADCOSIM_FMI_API_FMI_EXPORT_H_
#define QUADCOSIM_FMI_API_FMI_EXPORT_H_

#ifndef QUADCOSIM_FMI_EXPORT
#if defined(__GNUC__)
#define QUADCOSIM_FMI_EXPORT __attribute__((visibility("default")))
#else
#define QUADCOSIM_FMI_EXPORT
#endif
#endif

#endif /* QUADCOSIM_FMI_API_FMI_EXPORT_H_ */
