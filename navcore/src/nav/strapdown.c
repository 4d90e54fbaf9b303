/* placeholder: implemented in this issue */
typedef int nav_placeholder_strapdown;
