!> What the readers and scene.nml of `&body` and `&structure` do with the variables of a shape (centre,
!> size, rotation, rotation_axis, radius, axis, length, vertices, z_range; shape_geometry holds the shape).
module shape_input
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp
   use shape_geometry, only: shape_t, no_vertex, max_vertices
   use input_text, only: real_text, real_list_text, quoted
   implicit none
   private

   public :: shape_to_locals, locals_to_shape, vertex_given, vertex_list, shape_value

contains

   !> The numbers of a shape as the namelist variables of a group that takes one (&body, &structure). The
   !> vertices start empty: a list that is read replaces the shape's whole list (an override with fewer
   !> vertices leaves none of the old ones behind), a group without `vertices` keeps them (locals_to_shape).
   pure subroutine shape_to_locals(shape, centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range)
      type(shape_t), intent(in) :: shape
      real(rp), intent(out) :: centre(3), size(3), rotation, rotation_axis(3), radius, axis(3), length, &
                               vertices(2 * max_vertices), z_range(2)
      centre = shape%centre
      size = shape%size
      rotation = shape%rotation
      rotation_axis = shape%rotation_axis
      radius = shape%radius
      axis = shape%axis
      length = shape%length
      vertices = no_vertex
      z_range = shape%z_range
   end subroutine shape_to_locals

   !> The namelist variables read back into the shape (see shape_to_locals; its kind is read as text).
   pure subroutine locals_to_shape(centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range, shape)
      real(rp), intent(in) :: centre(3), size(3), rotation, rotation_axis(3), radius, axis(3), length, &
                              vertices(2 * max_vertices), z_range(2)
      type(shape_t), intent(inout) :: shape
      shape%centre = centre
      shape%size = size
      shape%rotation = rotation
      shape%rotation_axis = rotation_axis
      shape%radius = radius
      shape%axis = axis
      shape%length = length
      if (any(vertex_given(vertices))) shape%vertices = reshape(vertices, [2, max_vertices])
      shape%z_range = z_range
   end subroutine locals_to_shape

   !> A value of a vertex list that is not the 'none' marker (a NaN is given: validation reports it).
   elemental logical function vertex_given(value) result(given)
      real(rp), intent(in) :: value
      given = .true.
      if (ieee_is_finite(value)) given = value < no_vertex
   end function vertex_given

   !> The vertices as given, "x1, y1, x2, y2, ..." up to the first empty slot; none: a namelist null
   !> value "," (the variable keeps its default, no vertex).
   function vertex_list(vertices) result(text)
      real(rp), intent(in) :: vertices(:, :)
      character(len=:), allocatable :: text
      real(rp), allocatable :: flat(:)
      integer :: n
      flat = reshape(vertices, [size(vertices)])
      n = 0
      do while (n < size(flat))
         if (flat(n + 1) >= no_vertex) exit
         n = n + 1
      end do
      if (n == 0) then
         text = ','
      else
         text = real_list_text(flat(1:n))
      end if
   end function vertex_list

   !> The value of shape variable `name` (shape, centre, size, rotation, rotation_axis, radius, axis, length,
   !> vertices, z_range) as scene.nml writes it; '' for another name.
   function shape_value(shape, name) result(text)
      type(shape_t), intent(in) :: shape
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('shape')
         text = quoted(shape%kind)
      case ('centre')
         text = real_list_text(shape%centre)
      case ('size')
         text = real_list_text(shape%size)
      case ('rotation')
         text = real_text(shape%rotation)
      case ('rotation_axis')
         text = real_list_text(shape%rotation_axis)
      case ('radius')
         text = real_text(shape%radius)
      case ('axis')
         text = real_list_text(shape%axis)
      case ('length')
         text = real_text(shape%length)
      case ('vertices')
         text = vertex_list(shape%vertices)
      case ('z_range')
         text = real_list_text(shape%z_range)
      case default
         text = ''
      end select
   end function shape_value
end module shape_input
